//! [`Simd`], the vector operations the root list's queries (`traverse::root_list`) and the packs' lane test
//! (`tri4`) are written in, once, for two register widths: sixteen lanes of AVX-512
//! ([`Avx512`]) and eight of AVX2 ([`Avx2`]).
//! Each operation is the same IEEE arithmetic on every width, so both give the same bits.

use std::arch::x86_64::*;

use prism_math::Ray;

/// Lane operations of one width. Every one is `unsafe`: it may run only where the processor
/// has the width's instruction set. They are inlined into the queries, which are compiled
/// for it as a whole.
pub(crate) trait Simd {
    /// Lanes.
    const W: usize;
    /// A float per lane.
    type F: Copy;
    /// A 32-bit integer per lane.
    type I: Copy;
    /// A lane mask.
    type M: Copy;
    /// `W` floats: a vector's lanes in memory.
    type Floats: Default + AsRef<[f32]> + AsMut<[f32]>;

    /// Every lane `x`.
    unsafe fn splat(x: f32) -> Self::F;
    /// Every lane `x`.
    unsafe fn splat_i(x: i32) -> Self::I;
    /// `a + b`.
    unsafe fn add(a: Self::F, b: Self::F) -> Self::F;
    /// `a - b`.
    unsafe fn sub(a: Self::F, b: Self::F) -> Self::F;
    /// `a * b`.
    unsafe fn mul(a: Self::F, b: Self::F) -> Self::F;
    /// `a / b`.
    unsafe fn div(a: Self::F, b: Self::F) -> Self::F;
    /// The square root.
    unsafe fn sqrt(a: Self::F) -> Self::F;
    /// The smaller; `b` where either is NaN.
    unsafe fn min(a: Self::F, b: Self::F) -> Self::F;
    /// The larger; `b` where either is NaN.
    unsafe fn max(a: Self::F, b: Self::F) -> Self::F;
    /// The magnitude (sign bit cleared).
    unsafe fn abs(a: Self::F) -> Self::F;
    /// `a < b` (false for NaN).
    unsafe fn lt(a: Self::F, b: Self::F) -> Self::M;
    /// `a <= b` (false for NaN).
    unsafe fn le(a: Self::F, b: Self::F) -> Self::M;
    /// `a > b` (false for NaN).
    unsafe fn gt(a: Self::F, b: Self::F) -> Self::M;
    /// `a >= b` (false for NaN).
    unsafe fn ge(a: Self::F, b: Self::F) -> Self::M;
    /// `a == b` (false for NaN).
    unsafe fn eq(a: Self::F, b: Self::F) -> Self::M;
    /// `a >= b`, unsigned.
    unsafe fn ge_u32(a: Self::I, b: Self::I) -> Self::M;
    /// `m` and the lanes where `a` compares to `b` by predicate `P` (a `_CMP_*` constant):
    /// one masked compare with AVX-512, which keeps the mask out of general registers.
    unsafe fn cmp_and<const P: i32>(m: Self::M, a: Self::F, b: Self::F) -> Self::M;
    /// The lanes of `m` where `a`, `b` and `c` have the same sign bit.
    unsafe fn same_sign(m: Self::M, a: Self::F, b: Self::F, c: Self::F) -> Self::M;
    /// The lanes where `a`, `b` and `c` do not all have the same sign bit, as bits (lane 0
    /// lowest): [`Simd::same_sign`]'s complement, straight to bits.
    unsafe fn sign_differs(a: Self::F, b: Self::F, c: Self::F) -> u16;
    /// `b` in the lanes of `m`, `a` in the others.
    unsafe fn select(m: Self::M, a: Self::F, b: Self::F) -> Self::F;
    /// `b` in the lanes of `m`, `a` in the others.
    unsafe fn select_i(m: Self::M, a: Self::I, b: Self::I) -> Self::I;
    /// `b` in the lanes where `s` has its sign bit set, `a` in the others.
    unsafe fn select_sign(s: Self::F, a: Self::F, b: Self::F) -> Self::F;
    /// No lane.
    unsafe fn none() -> Self::M;
    /// Every lane.
    unsafe fn all() -> Self::M;
    /// Lanes in both.
    unsafe fn and(a: Self::M, b: Self::M) -> Self::M;
    /// Lanes in either.
    unsafe fn or(a: Self::M, b: Self::M) -> Self::M;
    /// Lanes in `a` and not in `b`.
    unsafe fn and_not(a: Self::M, b: Self::M) -> Self::M;
    /// The lanes as bits, lane 0 lowest.
    unsafe fn bits(m: Self::M) -> u16;
    /// The mask of bits `b`, lane 0 lowest (bits past the width are ignored).
    unsafe fn from_bits(b: u16) -> Self::M;
    /// The least of `v`'s lanes in `m` (infinity for no lane).
    unsafe fn min_of(m: Self::M, v: Self::F) -> f32;
    /// Lane i takes lane `idx[i]` of `v` (indices 0 to 3).
    unsafe fn permute(idx: Self::I, v: Self::F) -> Self::F;
    /// The four floats repeated across the lanes (lane i holds `p[i % 4]`).
    unsafe fn broadcast4(p: &[f32; 4]) -> Self::F;
    /// Lane i takes float `k` of ray i (of `W` rays).
    unsafe fn ray_field(rays: &[Ray], k: usize) -> Self::F;
    /// The first `W` floats of `s`.
    unsafe fn load(s: &[f32]) -> Self::F;
    /// Writes the lanes to the first `W` floats of `out`.
    unsafe fn store(v: Self::F, out: &mut [f32]);
    /// Writes the lanes to the first `W` integers of `out`.
    unsafe fn store_i(v: Self::I, out: &mut [u32]);
}

/// The float offsets of the lanes' rays (a [`Ray`] is six floats).
const RAY_FLOATS: [i32; 16] = [0, 6, 12, 18, 24, 30, 36, 42, 48, 54, 60, 66, 72, 78, 84, 90];
const _: () = assert!(std::mem::size_of::<Ray>() == 24);

/// Sixteen lanes of AVX-512 (F; masks in mask registers).
pub(crate) struct Avx512;

impl Simd for Avx512 {
    const W: usize = 16;
    type F = __m512;
    type I = __m512i;
    type M = __mmask16;
    type Floats = [f32; 16];

    #[inline(always)]
    unsafe fn splat(x: f32) -> __m512 {
        _mm512_set1_ps(x)
    }
    #[inline(always)]
    unsafe fn splat_i(x: i32) -> __m512i {
        _mm512_set1_epi32(x)
    }
    #[inline(always)]
    unsafe fn add(a: __m512, b: __m512) -> __m512 {
        _mm512_add_ps(a, b)
    }
    #[inline(always)]
    unsafe fn sub(a: __m512, b: __m512) -> __m512 {
        _mm512_sub_ps(a, b)
    }
    #[inline(always)]
    unsafe fn mul(a: __m512, b: __m512) -> __m512 {
        _mm512_mul_ps(a, b)
    }
    #[inline(always)]
    unsafe fn div(a: __m512, b: __m512) -> __m512 {
        _mm512_div_ps(a, b)
    }
    #[inline(always)]
    unsafe fn sqrt(a: __m512) -> __m512 {
        _mm512_sqrt_ps(a)
    }
    #[inline(always)]
    unsafe fn min(a: __m512, b: __m512) -> __m512 {
        _mm512_min_ps(a, b)
    }
    #[inline(always)]
    unsafe fn max(a: __m512, b: __m512) -> __m512 {
        _mm512_max_ps(a, b)
    }
    #[inline(always)]
    unsafe fn abs(a: __m512) -> __m512 {
        _mm512_abs_ps(a)
    }
    #[inline(always)]
    unsafe fn lt(a: __m512, b: __m512) -> __mmask16 {
        _mm512_cmp_ps_mask::<_CMP_LT_OQ>(a, b)
    }
    #[inline(always)]
    unsafe fn le(a: __m512, b: __m512) -> __mmask16 {
        _mm512_cmp_ps_mask::<_CMP_LE_OQ>(a, b)
    }
    #[inline(always)]
    unsafe fn gt(a: __m512, b: __m512) -> __mmask16 {
        _mm512_cmp_ps_mask::<_CMP_GT_OQ>(a, b)
    }
    #[inline(always)]
    unsafe fn ge(a: __m512, b: __m512) -> __mmask16 {
        _mm512_cmp_ps_mask::<_CMP_GE_OQ>(a, b)
    }
    #[inline(always)]
    unsafe fn eq(a: __m512, b: __m512) -> __mmask16 {
        _mm512_cmp_ps_mask::<_CMP_EQ_OQ>(a, b)
    }
    #[inline(always)]
    unsafe fn ge_u32(a: __m512i, b: __m512i) -> __mmask16 {
        _mm512_cmpge_epu32_mask(a, b)
    }
    #[inline(always)]
    unsafe fn cmp_and<const P: i32>(m: __mmask16, a: __m512, b: __m512) -> __mmask16 {
        _mm512_mask_cmp_ps_mask::<P>(m, a, b)
    }
    #[inline(always)]
    unsafe fn same_sign(m: __mmask16, a: __m512, b: __m512, c: __m512) -> __mmask16 {
        let [a, b, c] = [a, b, c].map(|x| _mm512_castps_si512(x));
        // `(a ^ b) | (a ^ c)`: every bit but those where the three agree.
        let differ = _mm512_ternarylogic_epi32::<0x7e>(a, b, c);
        _mm512_mask_testn_epi32_mask(m, differ, _mm512_set1_epi32(i32::MIN))
    }
    #[inline(always)]
    unsafe fn sign_differs(a: __m512, b: __m512, c: __m512) -> u16 {
        let [a, b, c] = [a, b, c].map(|x| _mm512_castps_si512(x));
        let differ = _mm512_ternarylogic_epi32::<0x7e>(a, b, c);
        _mm512_test_epi32_mask(differ, _mm512_set1_epi32(i32::MIN))
    }
    #[inline(always)]
    unsafe fn select(m: __mmask16, a: __m512, b: __m512) -> __m512 {
        _mm512_mask_blend_ps(m, a, b)
    }
    #[inline(always)]
    unsafe fn select_i(m: __mmask16, a: __m512i, b: __m512i) -> __m512i {
        _mm512_mask_blend_epi32(m, a, b)
    }
    #[inline(always)]
    unsafe fn select_sign(s: __m512, a: __m512, b: __m512) -> __m512 {
        let neg = _mm512_cmplt_epi32_mask(_mm512_castps_si512(s), _mm512_setzero_si512());
        _mm512_mask_blend_ps(neg, a, b)
    }
    #[inline(always)]
    unsafe fn none() -> __mmask16 {
        0
    }
    #[inline(always)]
    unsafe fn all() -> __mmask16 {
        u16::MAX
    }
    #[inline(always)]
    unsafe fn and(a: __mmask16, b: __mmask16) -> __mmask16 {
        a & b
    }
    #[inline(always)]
    unsafe fn or(a: __mmask16, b: __mmask16) -> __mmask16 {
        a | b
    }
    #[inline(always)]
    unsafe fn and_not(a: __mmask16, b: __mmask16) -> __mmask16 {
        a & !b
    }
    #[inline(always)]
    unsafe fn bits(m: __mmask16) -> u16 {
        m
    }
    #[inline(always)]
    unsafe fn from_bits(b: u16) -> __mmask16 {
        b
    }
    #[inline(always)]
    unsafe fn min_of(m: __mmask16, v: __m512) -> f32 {
        _mm512_mask_reduce_min_ps(m, v)
    }
    #[inline(always)]
    unsafe fn permute(idx: __m512i, v: __m512) -> __m512 {
        _mm512_permutexvar_ps(idx, v)
    }
    #[inline(always)]
    unsafe fn broadcast4(p: &[f32; 4]) -> __m512 {
        // SAFETY: `p` is four floats.
        _mm512_broadcast_f32x4(unsafe { _mm_loadu_ps(p.as_ptr()) })
    }
    #[inline(always)]
    unsafe fn ray_field(rays: &[Ray], k: usize) -> __m512 {
        debug_assert!(rays.len() >= 16 && k < 6);
        // SAFETY: lane i reads float 6i + k of `rays`, within ray i of sixteen.
        unsafe {
            let index = _mm512_loadu_si512(RAY_FLOATS.as_ptr().cast());
            _mm512_i32gather_ps::<4>(index, rays.as_ptr().cast::<f32>().add(k))
        }
    }
    #[inline(always)]
    unsafe fn load(s: &[f32]) -> __m512 {
        assert!(s.len() >= 16);
        // SAFETY: sixteen floats are read from a slice of at least sixteen.
        unsafe { _mm512_loadu_ps(s.as_ptr()) }
    }
    #[inline(always)]
    unsafe fn store(v: __m512, out: &mut [f32]) {
        assert!(out.len() >= 16);
        // SAFETY: sixteen floats are written into a slice of at least sixteen.
        unsafe { _mm512_storeu_ps(out.as_mut_ptr(), v) }
    }
    #[inline(always)]
    unsafe fn store_i(v: __m512i, out: &mut [u32]) {
        assert!(out.len() >= 16);
        // SAFETY: sixteen integers are written into a slice of at least sixteen.
        unsafe { _mm512_storeu_si512(out.as_mut_ptr().cast(), v) }
    }
}

/// Eight lanes of AVX2; a mask is a vector with every bit of a lane set where it is in.
pub(crate) struct Avx2;

impl Simd for Avx2 {
    const W: usize = 8;
    type F = __m256;
    type I = __m256i;
    type M = __m256;
    type Floats = [f32; 8];

    #[inline(always)]
    unsafe fn splat(x: f32) -> __m256 {
        _mm256_set1_ps(x)
    }
    #[inline(always)]
    unsafe fn splat_i(x: i32) -> __m256i {
        _mm256_set1_epi32(x)
    }
    #[inline(always)]
    unsafe fn add(a: __m256, b: __m256) -> __m256 {
        _mm256_add_ps(a, b)
    }
    #[inline(always)]
    unsafe fn sub(a: __m256, b: __m256) -> __m256 {
        _mm256_sub_ps(a, b)
    }
    #[inline(always)]
    unsafe fn mul(a: __m256, b: __m256) -> __m256 {
        _mm256_mul_ps(a, b)
    }
    #[inline(always)]
    unsafe fn div(a: __m256, b: __m256) -> __m256 {
        _mm256_div_ps(a, b)
    }
    #[inline(always)]
    unsafe fn sqrt(a: __m256) -> __m256 {
        _mm256_sqrt_ps(a)
    }
    #[inline(always)]
    unsafe fn min(a: __m256, b: __m256) -> __m256 {
        _mm256_min_ps(a, b)
    }
    #[inline(always)]
    unsafe fn max(a: __m256, b: __m256) -> __m256 {
        _mm256_max_ps(a, b)
    }
    #[inline(always)]
    unsafe fn abs(a: __m256) -> __m256 {
        _mm256_and_ps(a, _mm256_castsi256_ps(_mm256_set1_epi32(0x7fff_ffff)))
    }
    #[inline(always)]
    unsafe fn lt(a: __m256, b: __m256) -> __m256 {
        _mm256_cmp_ps::<_CMP_LT_OQ>(a, b)
    }
    #[inline(always)]
    unsafe fn cmp_and<const P: i32>(m: __m256, a: __m256, b: __m256) -> __m256 {
        _mm256_and_ps(m, _mm256_cmp_ps::<P>(a, b))
    }
    #[inline(always)]
    unsafe fn same_sign(m: __m256, a: __m256, b: __m256, c: __m256) -> __m256 {
        let differ = _mm256_or_ps(_mm256_xor_ps(a, b), _mm256_xor_ps(a, c));
        // Every bit of a lane set where the sign bits differ.
        let differ = _mm256_srai_epi32::<31>(_mm256_castps_si256(differ));
        _mm256_andnot_ps(_mm256_castsi256_ps(differ), m)
    }
    #[inline(always)]
    unsafe fn sign_differs(a: __m256, b: __m256, c: __m256) -> u16 {
        _mm256_movemask_ps(_mm256_or_ps(_mm256_xor_ps(a, b), _mm256_xor_ps(a, c))) as u16
    }
    #[inline(always)]
    unsafe fn le(a: __m256, b: __m256) -> __m256 {
        _mm256_cmp_ps::<_CMP_LE_OQ>(a, b)
    }
    #[inline(always)]
    unsafe fn gt(a: __m256, b: __m256) -> __m256 {
        _mm256_cmp_ps::<_CMP_GT_OQ>(a, b)
    }
    #[inline(always)]
    unsafe fn ge(a: __m256, b: __m256) -> __m256 {
        _mm256_cmp_ps::<_CMP_GE_OQ>(a, b)
    }
    #[inline(always)]
    unsafe fn eq(a: __m256, b: __m256) -> __m256 {
        _mm256_cmp_ps::<_CMP_EQ_OQ>(a, b)
    }
    #[inline(always)]
    unsafe fn ge_u32(a: __m256i, b: __m256i) -> __m256 {
        // Unsigned order is signed order with the top bits flipped.
        let flip = _mm256_set1_epi32(i32::MIN);
        let below = _mm256_cmpgt_epi32(_mm256_xor_si256(b, flip), _mm256_xor_si256(a, flip));
        _mm256_andnot_ps(_mm256_castsi256_ps(below), Self::all())
    }
    #[inline(always)]
    unsafe fn select(m: __m256, a: __m256, b: __m256) -> __m256 {
        _mm256_blendv_ps(a, b, m)
    }
    #[inline(always)]
    unsafe fn select_i(m: __m256, a: __m256i, b: __m256i) -> __m256i {
        _mm256_castps_si256(_mm256_blendv_ps(
            _mm256_castsi256_ps(a),
            _mm256_castsi256_ps(b),
            m,
        ))
    }
    #[inline(always)]
    unsafe fn select_sign(s: __m256, a: __m256, b: __m256) -> __m256 {
        _mm256_blendv_ps(a, b, s)
    }
    #[inline(always)]
    unsafe fn none() -> __m256 {
        _mm256_setzero_ps()
    }
    #[inline(always)]
    unsafe fn all() -> __m256 {
        _mm256_castsi256_ps(_mm256_set1_epi32(-1))
    }
    #[inline(always)]
    unsafe fn and(a: __m256, b: __m256) -> __m256 {
        _mm256_and_ps(a, b)
    }
    #[inline(always)]
    unsafe fn or(a: __m256, b: __m256) -> __m256 {
        _mm256_or_ps(a, b)
    }
    #[inline(always)]
    unsafe fn and_not(a: __m256, b: __m256) -> __m256 {
        _mm256_andnot_ps(b, a)
    }
    #[inline(always)]
    unsafe fn bits(m: __m256) -> u16 {
        _mm256_movemask_ps(m) as u16
    }
    #[inline(always)]
    unsafe fn from_bits(b: u16) -> __m256 {
        let lane_bits = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
        let set = _mm256_and_si256(_mm256_set1_epi32(i32::from(b)), lane_bits);
        _mm256_castsi256_ps(_mm256_cmpeq_epi32(set, lane_bits))
    }
    #[inline(always)]
    unsafe fn min_of(m: __m256, v: __m256) -> f32 {
        let v = _mm256_blendv_ps(_mm256_set1_ps(f32::INFINITY), v, m);
        let h = _mm_min_ps(_mm256_castps256_ps128(v), _mm256_extractf128_ps::<1>(v));
        let h = _mm_min_ps(h, _mm_movehl_ps(h, h));
        let h = _mm_min_ss(h, _mm_shuffle_ps::<1>(h, h));
        _mm_cvtss_f32(h)
    }
    #[inline(always)]
    unsafe fn permute(idx: __m256i, v: __m256) -> __m256 {
        _mm256_permutevar8x32_ps(v, idx)
    }
    #[inline(always)]
    unsafe fn broadcast4(p: &[f32; 4]) -> __m256 {
        // SAFETY: `p` is four floats.
        _mm256_broadcast_ps(&unsafe { _mm_loadu_ps(p.as_ptr()) })
    }
    #[inline(always)]
    unsafe fn ray_field(rays: &[Ray], k: usize) -> __m256 {
        debug_assert!(rays.len() >= 8 && k < 6);
        // SAFETY: lane i reads float 6i + k of `rays`, within ray i of eight.
        unsafe {
            let index = _mm256_loadu_si256(RAY_FLOATS.as_ptr().cast());
            _mm256_i32gather_ps::<4>(rays.as_ptr().cast::<f32>().add(k), index)
        }
    }
    #[inline(always)]
    unsafe fn load(s: &[f32]) -> __m256 {
        assert!(s.len() >= 8);
        // SAFETY: eight floats are read from a slice of at least eight.
        unsafe { _mm256_loadu_ps(s.as_ptr()) }
    }
    #[inline(always)]
    unsafe fn store(v: __m256, out: &mut [f32]) {
        assert!(out.len() >= 8);
        // SAFETY: eight floats are written into a slice of at least eight.
        unsafe { _mm256_storeu_ps(out.as_mut_ptr(), v) }
    }
    #[inline(always)]
    unsafe fn store_i(v: __m256i, out: &mut [u32]) {
        assert!(out.len() >= 8);
        // SAFETY: eight integers are written into a slice of at least eight.
        unsafe { _mm256_storeu_si256(out.as_mut_ptr().cast(), v) }
    }
}
