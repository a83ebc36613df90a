//! [`prefetch`], a hint that starts loading memory a kernel will read soon, so that
//! independent cache misses overlap instead of waiting one after another.

/// Starts loading the cache line holding `p` into every cache level. A hint only: it never
/// faults, whatever the address, and does nothing on processors other than x86-64.
#[inline(always)]
pub fn prefetch<T>(p: *const T) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a prefetch is only a hint; it reads nothing the program sees and never
    // faults, whatever the address.
    unsafe {
        std::arch::x86_64::_mm_prefetch::<{ std::arch::x86_64::_MM_HINT_T0 }>(p.cast());
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = p;
}
