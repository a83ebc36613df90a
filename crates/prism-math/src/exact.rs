//! [`ExactSum`]: sums of 32-bit floats in fixed point, exact, so that any order of adding
//! gives the same bits.

/// Fraction bits of the fixed point: values are counted in units of 2^-50.
const FRACTION_BITS: i32 = 50;
/// 2^50, the fixed point's scale.
const SCALE: f64 = 1_125_899_906_842_624.0;

/// An exact sum of `f32` values: each value is held in units of 2^-50 (bits below that are
/// dropped, towards zero), and integers add exactly, so a sum split into parts and added in
/// any order has the same bits. Values of magnitude 2^55 (3.6e16) or more, and non-finite
/// ones, are not representable: [`ExactSum::add`] refuses them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct ExactSum(pub i128);

impl ExactSum {
    /// The largest magnitude (exclusive) a value added may have.
    pub const LIMIT: f32 = 36_028_797_018_963_968.0; // 2^55

    /// The value `x` in fixed point, or `None` if it is not finite or `|x| >= LIMIT`.
    #[inline]
    #[must_use]
    pub fn fixed(x: f32) -> Option<i128> {
        // Below 2^13 the value fits in 64 bits: one exact scaling and one truncation (as
        // the general path below truncates towards zero).
        let v = f64::from(x) * SCALE;
        if v.abs() < 9_223_372_036_854_775_808.0 {
            // SAFETY: `v` is finite (NaN fails the test above) and below 2^63 in magnitude,
            // so its truncation is an i64: the value `v as i64` gives, without the checks
            // for saturation.
            return Some(i128::from(unsafe { v.to_int_unchecked::<i64>() }));
        }
        let bits = x.to_bits();
        let exp = ((bits >> 23) & 0xff) as i32;
        // x = mant * 2^(max(exp, 1) - 150); 2^55 has exp 182.
        if exp >= 182 {
            return None;
        }
        let mant = i128::from(if exp == 0 {
            bits & 0x7f_ffff
        } else {
            (bits & 0x7f_ffff) | 0x80_0000
        });
        let shift = exp.max(1) - 150 + FRACTION_BITS;
        let mag = if shift >= 0 {
            mant << shift
        } else if shift > -32 {
            mant >> -shift
        } else {
            0
        };
        Some(if bits >> 31 == 1 { -mag } else { mag })
    }

    /// Adds `x`; returns false, adding nothing, if `x` is not representable.
    #[inline]
    pub fn add(&mut self, x: f32) -> bool {
        match ExactSum::fixed(x) {
            Some(v) => {
                self.0 += v;
                true
            }
            None => false,
        }
    }

    /// The sum as a float, rounded to nearest.
    #[must_use]
    pub fn value(self) -> f64 {
        // Both conversions round to nearest; the 64-bit one is one instruction, and the
        // 128-bit one (a library call) is kept off the common path.
        #[cold]
        #[inline(never)]
        fn wide(v: i128) -> f64 {
            v as f64 / SCALE
        }
        let small = self.0 as i64;
        if i128::from(small) == self.0 {
            small as f64 / SCALE
        } else {
            wide(self.0)
        }
    }

    /// The sum divided by `n`, rounded to a float (0 for `n` = 0).
    #[must_use]
    pub fn mean(self, n: u32) -> f32 {
        if n == 0 {
            return 0.0;
        }
        (self.value() / f64::from(n)) as f32
    }

    /// The sum as four 32-bit words, least significant first (for storage).
    #[must_use]
    pub fn words(self) -> [u32; 4] {
        let v = self.0 as u128;
        [
            v as u32,
            (v >> 32) as u32,
            (v >> 64) as u32,
            (v >> 96) as u32,
        ]
    }

    /// The sum from the words of [`ExactSum::words`].
    #[must_use]
    pub fn from_words(w: [u32; 4]) -> ExactSum {
        let v = u128::from(w[0])
            | u128::from(w[1]) << 32
            | u128::from(w[2]) << 64
            | u128::from(w[3]) << 96;
        ExactSum(v as i128)
    }
}

impl std::ops::AddAssign for ExactSum {
    fn add_assign(&mut self, other: ExactSum) {
        self.0 += other.0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Oracle: double precision. Every float at or above 2^-26 in magnitude (24 significant
    /// bits within the 2^-50 grid) is held exactly; smaller ones lose only what is below
    /// 2^-50; the limit and non-finite values are refused.
    #[test]
    fn fixed_point_holds_floats_exactly() {
        let mut state = 0x1234_5678_9abc_def0u64;
        for _ in 0..200_000 {
            state = crate::mix64(state);
            let x = f32::from_bits(state as u32);
            match ExactSum::fixed(x) {
                None => assert!(!x.is_finite() || x.abs() >= ExactSum::LIMIT, "{x}"),
                Some(v) => {
                    let back = v as f64 * 2f64.powi(-50);
                    if x.abs() >= 2f32.powi(-26) {
                        assert_eq!(back, f64::from(x), "{x}");
                    } else {
                        assert!((back - f64::from(x)).abs() < 2f64.powi(-50), "{x}");
                    }
                }
            }
        }
        assert_eq!(SCALE, 2f64.powi(FRACTION_BITS));
        assert_eq!(ExactSum::fixed(-0.0), Some(0));
        assert_eq!(ExactSum::fixed(1.5), Some(3 << 49));
        assert!(ExactSum::fixed(ExactSum::LIMIT).is_none());
        assert!(ExactSum::fixed(ExactSum::LIMIT * 0.999_999_9).is_some());
    }

    /// Property: a sum split anywhere and added in any order has the same bits; the words
    /// round-trip.
    #[test]
    fn sums_do_not_depend_on_order() {
        let values: Vec<f32> = (0..1000u64)
            .map(|i| {
                let h = crate::mix64(i);
                (h >> 40) as f32 * 2f32.powi((h % 40) as i32 - 30)
            })
            .collect();
        let mut whole = ExactSum::default();
        for &v in &values {
            assert!(whole.add(v));
        }
        for cut in [1, 333, 999] {
            let (mut a, mut b) = (ExactSum::default(), ExactSum::default());
            for &v in values[..cut].iter().rev() {
                a.add(v);
            }
            for &v in &values[cut..] {
                b.add(v);
            }
            b += a;
            assert_eq!(b, whole);
        }
        assert_eq!(ExactSum::from_words(whole.words()), whole);
        let neg = ExactSum(-12_345_678_901_234_567_890_123);
        assert_eq!(ExactSum::from_words(neg.words()), neg);
        let exact: f64 = values.iter().map(|&v| f64::from(v)).sum();
        assert!((whole.value() - exact).abs() <= 1e-12 * exact.abs());
    }
}
