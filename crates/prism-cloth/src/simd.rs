//! The cloth's one intrinsics kernel: the spring force law on four springs in one AVX
//! vector per quantity. The only file of this crate that touches `std::arch`.

#[cfg(target_arch = "x86_64")]
use std::arch::x86_64::{
    _mm256_add_pd, _mm256_and_pd, _mm256_cmp_pd, _mm256_div_pd, _mm256_loadu_pd, _mm256_mul_pd,
    _mm256_setzero_pd, _mm256_sqrt_pd, _mm256_storeu_pd, _mm256_sub_pd, _CMP_NEQ_UQ,
};

/// The force law `k (|d| - rest) d / |d|` of four springs at once, from their `d = pb - pa`
/// per axis, rest lengths and stiffnesses (`lanes`: `[dx, dy, dz, rest, k]`), into the
/// force's `x`, `y` and `z` lanes; zero for a spring of length zero. Each lane is the scalar
/// law's operations in the scalar law's order, so the results are bit for bit the same.
///
/// # Safety
/// The processor must support AVX.
#[cfg(target_arch = "x86_64")]
#[inline]
#[target_feature(enable = "avx")]
pub(crate) unsafe fn spring_law_avx(
    lanes: &[[f64; 4]; 5],
    x: &mut [f64; 4],
    y: &mut [f64; 4],
    z: &mut [f64; 4],
) {
    // SAFETY: every pointer is to an array of four f64.
    unsafe {
        let [dx, dy, dz, rest, k] = lanes.map(|a| _mm256_loadu_pd(a.as_ptr()));
        let len = _mm256_sqrt_pd(_mm256_add_pd(
            _mm256_add_pd(_mm256_mul_pd(dx, dx), _mm256_mul_pd(dy, dy)),
            _mm256_mul_pd(dz, dz),
        ));
        let scale = _mm256_mul_pd(k, _mm256_sub_pd(len, rest));
        let live = _mm256_cmp_pd::<_CMP_NEQ_UQ>(len, _mm256_setzero_pd());
        let axis = |d| _mm256_and_pd(live, _mm256_mul_pd(scale, _mm256_div_pd(d, len)));
        _mm256_storeu_pd(x.as_mut_ptr(), axis(dx));
        _mm256_storeu_pd(y.as_mut_ptr(), axis(dy));
        _mm256_storeu_pd(z.as_mut_ptr(), axis(dz));
    }
}
