//! The order a walk visits the children of a node it entered, nearest first: a sorting
//! network on AVX2 lanes for three or more children.

/// A child waiting on a walk's stack: its reference and its entry distance.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub(crate) struct Pending {
    /// The child's reference (a node, or a leaf with `LEAF` set).
    pub(crate) node: u32,
    /// Where the ray enters the child's box.
    pub(crate) t_near: f32,
}

/// The number of set bits of each byte (the walks are compiled without `popcnt`).
#[cfg(target_arch = "x86_64")]
pub(crate) static BITS_SET: [u8; 256] = {
    let mut table = [0u8; 256];
    let mut i = 0;
    while i < 256 {
        table[i] = (i as u32).count_ones() as u8;
        i += 1;
    }
    table
};

/// Whether lane `lane` keeps the larger of itself and lane `lane ^ j` at step `(k, j)` of
/// a bitonic sort of eight lanes into descending order.
#[cfg(target_arch = "x86_64")]
pub(crate) const fn takes_max(lane: i32, k: i32, j: i32) -> bool {
    ((lane & j) == 0) == ((lane & k) == 0)
}

/// The lanes of step `(k, j)` that keep the larger value, as a blend mask.
#[cfg(target_arch = "x86_64")]
pub(crate) const fn max_lanes(k: i32, j: i32) -> i32 {
    let mut mask = 0;
    let mut lane = 0;
    while lane < 8 {
        if takes_max(lane, k, j) {
            mask |= 1 << lane;
        }
        lane += 1;
    }
    mask
}

/// Orders the children of `mask` (at least three of the eight slots) by their entries
/// `near`, farthest first, and writes them to `out`, the nearest last: the first `n - 1`
/// of the `n` children are the ones to push, in order, and the rest of `out` is scratch.
/// Returns the nearest child and `n - 1`. The order is descending by a key: the entry's
/// bits as an integer that orders as the floats do, the three lowest replaced by the
/// slot, so entries that differ only in those bits (less than 8 ulps apart) are ordered
/// by slot. No branch: a bitonic sorting network of six steps on the eight lanes, the
/// children not entered keyed below every entered one.
///
/// # Safety
/// The processor must support AVX2. No entered slot's entry may be NaN (the node tests
/// enter no such child).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(crate) unsafe fn sort_entered_avx2(
    near: &[f32; 8],
    child: &[u32; 8],
    mask: u32,
    out: &mut [std::mem::MaybeUninit<Pending>; 8],
) -> (u32, usize) {
    use std::arch::x86_64::{
        __m256i, _mm256_and_si256, _mm256_blend_epi32, _mm256_blendv_epi8, _mm256_castps_si256,
        _mm256_castsi256_si128, _mm256_cmpeq_epi32, _mm256_loadu_ps, _mm256_loadu_si256,
        _mm256_max_epi32, _mm256_min_epi32, _mm256_or_si256, _mm256_permute2x128_si256,
        _mm256_permutevar8x32_epi32, _mm256_permutevar8x32_ps, _mm256_set1_epi32,
        _mm256_setr_epi32, _mm256_shuffle_epi32, _mm256_srai_epi32, _mm256_srli_epi32,
        _mm256_storeu_si256, _mm256_unpackhi_epi32, _mm256_unpacklo_epi32, _mm256_xor_si256,
        _mm_cvtsi128_si32,
    };
    debug_assert!(BITS_SET[(mask & 0xff) as usize] >= 3 && mask < 256);
    debug_assert!((0..8).all(|s| mask & (1 << s) == 0 || !near[s].is_nan()));
    // SAFETY: the caller ensures AVX2; the loads read the eight floats of `near` and the
    // eight references of `child`, the stores the eight `Pending` (8 bytes each, `repr(C)`)
    // of `out`.
    unsafe {
        // One compare-exchange step: each lane and the one `$shuffle` brings it, the lanes
        // of `$k, $j` keeping the larger.
        macro_rules! step {
            ($v:expr, $partner:expr, $k:expr, $j:expr) => {{
                let v: __m256i = $v;
                let other = $partner;
                const MAX: i32 = max_lanes($k, $j);
                _mm256_blend_epi32::<MAX>(_mm256_min_epi32(v, other), _mm256_max_epi32(v, other))
            }};
        }
        let t = _mm256_loadu_ps(near.as_ptr());
        let bits = _mm256_castps_si256(t);
        let ordered = _mm256_xor_si256(bits, _mm256_srli_epi32::<1>(_mm256_srai_epi32::<31>(bits)));
        let slots = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
        let keys = _mm256_or_si256(_mm256_and_si256(ordered, _mm256_set1_epi32(!7)), slots);
        let bit = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
        let entered =
            _mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32(mask as i32), bit), bit);
        // An entered key is above `i32::MIN`: that would be a NaN entry.
        let mut v = _mm256_blendv_epi8(_mm256_set1_epi32(i32::MIN), keys, entered);
        v = step!(v, _mm256_shuffle_epi32::<0b10_11_00_01>(v), 2, 1);
        v = step!(v, _mm256_shuffle_epi32::<0b01_00_11_10>(v), 4, 2);
        v = step!(v, _mm256_shuffle_epi32::<0b10_11_00_01>(v), 4, 1);
        v = step!(v, _mm256_permute2x128_si256::<1>(v, v), 8, 4);
        v = step!(v, _mm256_shuffle_epi32::<0b01_00_11_10>(v), 8, 2);
        v = step!(v, _mm256_shuffle_epi32::<0b10_11_00_01>(v), 8, 1);
        let order = _mm256_and_si256(v, _mm256_set1_epi32(7));
        let kids = _mm256_permutevar8x32_epi32(_mm256_loadu_si256(child.as_ptr().cast()), order);
        let dist = _mm256_castps_si256(_mm256_permutevar8x32_ps(t, order));
        // Lanes [k0 t0 k1 t1 | k4 t4 k5 t5] and [k2 t2 k3 t3 | k6 t6 k7 t7], then halves
        // rejoined in order.
        let (lo, hi) = (
            _mm256_unpacklo_epi32(kids, dist),
            _mm256_unpackhi_epi32(kids, dist),
        );
        let dst = out.as_mut_ptr().cast::<__m256i>();
        _mm256_storeu_si256(dst, _mm256_permute2x128_si256::<0x20>(lo, hi));
        _mm256_storeu_si256(dst.add(1), _mm256_permute2x128_si256::<0x31>(lo, hi));
        let pushed = usize::from(BITS_SET[(mask & 0xff) as usize]) - 1;
        let at = _mm256_permutevar8x32_epi32(kids, _mm256_set1_epi32(pushed as i32));
        let nearest = _mm_cvtsi128_si32(_mm256_castsi256_si128(at)) as u32;
        (nearest, pushed)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The order key of entry distance `t` in slot `slot`: the float's bits as an integer
    /// that orders as the floats do (a negative float's other bits flipped), its three
    /// lowest bits replaced by the slot. Keys of distances 8 ulps apart or more order as
    /// the distances do; closer ones may be ordered by slot instead. [`sort_entered_avx2`]
    /// computes these keys on lanes.
    fn key(t: f32, slot: usize) -> i32 {
        let bits = t.to_bits() as i32;
        let ordered = bits ^ ((bits >> 31) as u32 >> 1) as i32;
        (ordered & !7) | slot as i32
    }

    /// Closed form: the bitonic network's step masks, against the rule written out.
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn step_masks_are_the_bitonic_network_s() {
        assert_eq!(max_lanes(2, 1), 0b1001_1001);
        assert_eq!(max_lanes(4, 2), 0b1100_0011);
        assert_eq!(max_lanes(4, 1), 0b1010_0101);
        assert_eq!(max_lanes(8, 4), 0b0000_1111);
        assert_eq!(max_lanes(8, 2), 0b0011_0011);
        assert_eq!(max_lanes(8, 1), 0b0101_0101);
    }

    /// Property: [`key`] orders floats as `<` does when they are more than 8 ulps apart
    /// (negative, zero, subnormal, infinite), ties going to the slot.
    #[test]
    fn keys_order_as_the_distances() {
        let values = [
            f32::NEG_INFINITY,
            -1e30,
            -2.5,
            -1e-30,
            -0.0,
            0.0,
            1e-40,
            1e-30,
            0.5,
            1.0,
            3.0e5,
            f32::MAX,
            f32::INFINITY,
        ];
        for (i, &a) in values.iter().enumerate() {
            for &b in &values[i + 1..] {
                if a == b {
                    assert!(key(a, 0) < key(b, 1));
                } else {
                    assert!(key(a, 7) < key(b, 0), "{a} < {b}");
                }
            }
        }
    }

    /// Brute force: the network's order equals sorting the entered children by [`key`],
    /// descending, over random entries (with ties, negative and infinite ones) and every
    /// mask of three or more children; the entries travel with their children.
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn network_sorts_as_the_brute_force_sort() {
        if !std::arch::is_x86_feature_detected!("avx2") {
            return;
        }
        let mut rng = prism_math::Pcg32::new(11, 3);
        let pool = [0.0, 1.0, 1.0, -2.0, 0.25, f32::INFINITY, 7.5e-41, 1e9];
        for round in 0..4000 {
            let near: [f32; 8] = std::array::from_fn(|_| {
                if round % 2 == 0 {
                    pool[(rng.next_f32() * 8.0) as usize % 8]
                } else {
                    (rng.next_f32() - 0.25) * 100.0
                }
            });
            let child: [u32; 8] = std::array::from_fn(|s| 1000 + s as u32 * 7 + round);
            let mask = (round * 37 + 7) % 256;
            if mask.count_ones() < 3 {
                continue;
            }
            let mut want: Vec<usize> = (0..8).filter(|&s| mask & (1 << s) != 0).collect();
            want.sort_by_key(|&s| std::cmp::Reverse(key(near[s], s)));
            let mut out = [std::mem::MaybeUninit::new(Pending {
                node: 0,
                t_near: 0.0,
            }); 8];
            // SAFETY: AVX2 was detected; no entry is NaN.
            let (nearest, pushed) = unsafe { sort_entered_avx2(&near, &child, mask, &mut out) };
            assert_eq!(pushed, want.len() - 1);
            for (i, &s) in want.iter().enumerate() {
                // SAFETY: the network wrote all eight.
                let got = unsafe { out[i].assume_init() };
                assert_eq!(got.node, child[s], "round {round} place {i}");
                assert_eq!(got.t_near.to_bits(), near[s].to_bits());
            }
            assert_eq!(nearest, child[want[pushed]]);
        }
    }
}
