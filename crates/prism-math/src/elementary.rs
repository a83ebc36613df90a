//! [`exp`], [`ln`], [`acos`] and [`atan2`] of one `f32` in plain arithmetic, without a library call:
//! the same operations run lane by lane on [`crate::lanes::F16`] (`F16::exp` and the
//! others) give the same bits, so SIMD kernels and scalar code agree exactly.

/// ln 2 split in two: the high part has its low 8 bits zero, so that `n * LN2_HI` is exact
/// for `|n| < 256`.
const LN2_HI: f32 = 0.693_145_75;
const LN2_LO: f32 = 1.428_606_8e-6;
const LOG2_E: f32 = std::f32::consts::LOG2_E;
/// Adding and subtracting 1.5 * 2^23 rounds a float of magnitude below 2^22 to an integer.
const ROUNDER: f32 = 12_582_912.0;

/// `2^n` for `-126 <= n <= 127`, from its bits.
#[inline(always)]
fn pow2(n: i32) -> f32 {
    f32::from_bits(((n + 127) as u32) << 23)
}

/// `e^x`, within 2 ulp of the exact value for normal results (0 below about -103.3,
/// infinity above about 88.7, NaN for NaN).
#[must_use]
#[inline(always)]
pub fn exp(x: f32) -> f32 {
    // Past these the result is 0 or infinite anyway; a NaN passes both tests unchanged.
    let x = if x < -104.0 { -104.0 } else { x };
    let x = if x > 89.0 { 89.0 } else { x };
    let n = (x * LOG2_E + ROUNDER) - ROUNDER;
    // x = n ln 2 + r, |r| <= ln 2 / 2 (plus rounding).
    let r = (x - n * LN2_HI) - n * LN2_LO;
    let p = 1.0
        + r * (1.0
            + r * (0.5
                + r * (1.0 / 6.0
                    + r * (1.0 / 24.0
                        + r * (1.0 / 120.0 + r * (1.0 / 720.0 + r * (1.0 / 5040.0)))))));
    // 2^n as two normal factors, so that huge and tiny results round once, at the end.
    let n = n as i32;
    let half = n >> 1;
    p * pow2(half) * pow2(n - half)
}

/// The natural logarithm, within 3 ulp (`-inf` at 0, NaN below 0 and for NaN, `inf` at
/// infinity).
#[must_use]
#[inline(always)]
pub fn ln(x: f32) -> f32 {
    // Subnormals are scaled into the normal range first.
    let tiny = x < f32::MIN_POSITIVE;
    let xs = if tiny { x * 8_388_608.0 } else { x };
    let bits = xs.to_bits();
    let e = ((bits >> 23) & 0xff) as i32 - 127 - if tiny { 23 } else { 0 };
    // x = m 2^e with m in [1, 2), then in [sqrt(1/2), sqrt(2)).
    let m = f32::from_bits((bits & 0x007f_ffff) | 0x3f80_0000);
    let big = m > std::f32::consts::SQRT_2;
    let m = if big { m * 0.5 } else { m };
    let e = if big { e + 1 } else { e };
    // ln m = 2 atanh(s), s = (m - 1) / (m + 1), |s| <= 0.172: its odd series.
    let s = (m - 1.0) / (m + 1.0);
    let s2 = s * s;
    let series = 2.0 * s * (1.0 + s2 * (1.0 / 3.0 + s2 * (0.2 + s2 * (1.0 / 7.0 + s2 / 9.0))));
    let ef = e as f32;
    let r = ef * LN2_HI + (series + ef * LN2_LO);
    if x == 0.0 {
        f32::NEG_INFINITY
    } else if x.is_nan() || x < 0.0 {
        f32::NAN
    } else if x == f32::INFINITY {
        x
    } else {
        r
    }
}

/// `acos x` for `-1 <= x <= 1`, within 1e-6 (Abramowitz and Stegun 4.4.46; NaN outside).
#[must_use]
#[inline(always)]
pub fn acos(x: f32) -> f32 {
    let a = x.abs();
    // The fit's constant term, a little below pi / 2.
    #[allow(clippy::approx_constant)]
    let p = 1.570_796_3
        + a * (-0.214_598_8
            + a * (0.088_978_99
                + a * (-0.050_174_303
                    + a * (0.030_891_88
                        + a * (-0.017_088_126 + a * (0.006_670_09 + a * -0.001_262_491_1))))));
    let r = (1.0 - a).sqrt() * p;
    if x < 0.0 {
        std::f32::consts::PI - r
    } else {
        r
    }
}

/// `atan2(y, x)` in `[-pi, pi]`, within 4e-7 of the exact angle (2 ulp at pi) (Abramowitz and Stegun
/// 4.4.49 on the octant, NaN for NaN); the sign of a zero `y` is kept, as `f32::atan2`'s.
#[must_use]
#[inline(always)]
pub fn atan2(y: f32, x: f32) -> f32 {
    let (ax, ay) = (x.abs(), y.abs());
    let steep = ay > ax;
    let (num, den) = if steep { (ax, ay) } else { (ay, ax) };
    let t = if den == 0.0 { 0.0 } else { num / den };
    let t2 = t * t;
    let r = t
        * (1.0
            + t2 * (-0.333_331_45
                + t2 * (0.199_935_51
                    + t2 * (-0.142_089
                        + t2 * (0.106_562_64
                            + t2 * (-0.075_289_64
                                + t2 * (0.042_909_614
                                    + t2 * (-0.016_165_737 + t2 * 0.002_866_225_7))))))));
    let r = if steep {
        std::f32::consts::FRAC_PI_2 - r
    } else {
        r
    };
    let r = if x.is_sign_negative() {
        std::f32::consts::PI - r
    } else {
        r
    };
    r.copysign(y)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The distance from `got` to `want` in units of the last place of `want` as an f32.
    fn ulps(got: f32, want: f64) -> f64 {
        let w = want as f32;
        let ulp = (f32::from_bits(w.abs().to_bits() + 1) - w.abs()) as f64;
        (f64::from(got) - want).abs() / ulp
    }

    /// Oracle: f64's `exp`, over the whole normal range, the subnormal edge and the
    /// special values.
    #[test]
    fn exp_is_within_two_ulp_of_f64() {
        let mut worst = 0.0f64;
        let mut x = -87.0f32;
        while x < 88.7 {
            worst = worst.max(ulps(exp(x), f64::from(x).exp()));
            x += 0.000_731;
        }
        assert!(worst <= 2.0, "worst {worst} ulp");
        for x in [0.0f32, -0.0, 1e-30, -1e-30, 1.0, -1.0] {
            assert!(ulps(exp(x), f64::from(x).exp()) <= 1.0, "{x}");
        }
        assert_eq!(exp(0.0), 1.0);
        assert_eq!(exp(-200.0), 0.0);
        assert_eq!(exp(f32::NEG_INFINITY), 0.0);
        assert_eq!(exp(100.0), f32::INFINITY);
        assert_eq!(exp(f32::INFINITY), f32::INFINITY);
        assert!(exp(f32::NAN).is_nan());
        // Subnormal results round once: near 2^-149 they are within one subnormal step.
        for x in [-100.0f32, -103.0, -95.5] {
            let want = f64::from(x).exp();
            assert!((f64::from(exp(x)) - want).abs() <= 1.5e-45, "{x}");
        }
    }

    /// Oracle: f64's `ln`, over normal and subnormal arguments and the special values.
    #[test]
    fn ln_is_within_three_ulp_of_f64() {
        let mut worst = 0.0f64;
        for k in 1..2000u32 {
            let x = f32::from_bits(k * 4099);
            worst = worst.max(ulps(ln(x), f64::from(x).ln()));
        }
        let mut x = 1.2e-38f32;
        while x < 3e38 {
            let want = f64::from(x).ln();
            // Near 1 the result is near 0: measure against its own size.
            worst = worst.max(ulps(ln(x), want));
            x *= 1.000_37;
        }
        let mut x = 0.5f32;
        while x < 2.0 {
            worst = worst.max(ulps(ln(x), f64::from(x).ln()));
            x += 0.000_013;
        }
        assert!(worst <= 3.0, "worst {worst} ulp");
        assert_eq!(ln(1.0), 0.0);
        assert_eq!(ln(0.0), f32::NEG_INFINITY);
        assert_eq!(ln(f32::INFINITY), f32::INFINITY);
        assert!(ln(-1.0).is_nan() && ln(f32::NAN).is_nan());
    }

    /// Oracle: f64's `acos` on [-1, 1].
    #[test]
    fn acos_is_within_1e_6_of_f64() {
        let mut x = -1.0f32;
        while x <= 1.0 {
            let err = (f64::from(acos(x)) - f64::from(x).acos()).abs();
            assert!(err < 1e-6, "acos {x}: off by {err}");
            x += 0.000_37;
        }
        assert_eq!(acos(1.0), 0.0);
        assert!(acos(1.5).is_nan());
    }

    /// Oracle: f64's `atan2`, around the circle at several radii, on the axes and at the
    /// signed zeros.
    #[test]
    fn atan2_is_within_4e_7_of_f64() {
        let mut worst = 0.0f64;
        for k in 0..200_000 {
            let a = k as f64 * std::f64::consts::TAU / 200_000.0 - std::f64::consts::PI;
            for r in [1e-3f64, 1.0, 7.5e3] {
                let (y, x) = ((a.sin() * r) as f32, (a.cos() * r) as f32);
                let want = f64::from(y).atan2(f64::from(x));
                worst = worst.max((f64::from(atan2(y, x)) - want).abs());
            }
        }
        assert!(worst < 4e-7, "worst {worst}");
        for (y, x) in [
            (0.0f32, 1.0f32),
            (-0.0, 1.0),
            (0.0, -1.0),
            (-0.0, -1.0),
            (1.0, 0.0),
            (-1.0, 0.0),
        ] {
            assert_eq!(atan2(y, x), y.atan2(x), "{y} {x}");
        }
        assert!(atan2(f32::NAN, 1.0).is_nan() && atan2(1.0, f32::NAN).is_nan());
    }
}
