//! Compositing: source-over, and the colour mixing of each `mix-blend-mode` (W3C
//! Compositing and Blending Level 1), on premultiplied RGBA in [0, 1].

use crate::document::BlendMode;

/// Premultiplied `src` over `dst`.
#[inline]
pub(crate) fn over(dst: &mut [f32; 4], src: [f32; 4]) {
    if src[3] >= 1.0 {
        *dst = src;
    } else if src[3] > 0.0 {
        let k = 1.0 - src[3];
        for c in 0..4 {
            dst[c] = src[c] + dst[c] * k;
        }
    }
}

/// Composites premultiplied `src` onto premultiplied `dst` with `mode`.
#[inline]
pub(crate) fn composite(dst: &mut [f32; 4], src: [f32; 4], mode: BlendMode) {
    let (sa, da) = (src[3], dst[3]);
    if sa <= 0.0 {
        return;
    }
    match mode {
        BlendMode::Normal => over(dst, src),
        BlendMode::PlusLighter => {
            for c in 0..4 {
                dst[c] = (dst[c] + src[c]).min(1.0);
            }
        }
        _ => {
            let un = |v: [f32; 4], a: f32| {
                if a > 0.0 {
                    [v[0] / a, v[1] / a, v[2] / a]
                } else {
                    [0.0; 3]
                }
            };
            let (cs, cb) = (un(src, sa), un(*dst, da));
            let mixed = mix(mode, cb, cs);
            for c in 0..3 {
                dst[c] = src[c] * (1.0 - da) + dst[c] * (1.0 - sa) + sa * da * mixed[c];
            }
            dst[3] = sa + da * (1.0 - sa);
        }
    }
}

/// `B(Cb, Cs)`: the mixed colour of backdrop `b` and source `s` (straight colours).
fn mix(mode: BlendMode, b: [f32; 3], s: [f32; 3]) -> [f32; 3] {
    let sep = |f: fn(f32, f32) -> f32| [f(b[0], s[0]), f(b[1], s[1]), f(b[2], s[2])];
    match mode {
        BlendMode::Normal | BlendMode::PlusLighter => s,
        BlendMode::Multiply => sep(|b, s| b * s),
        BlendMode::Screen => sep(screen),
        BlendMode::Overlay => sep(|b, s| hard_light(s, b)),
        BlendMode::Darken => sep(f32::min),
        BlendMode::Lighten => sep(f32::max),
        BlendMode::ColorDodge => sep(|b, s| {
            if b <= 0.0 {
                0.0
            } else if s >= 1.0 {
                1.0
            } else {
                (b / (1.0 - s)).min(1.0)
            }
        }),
        BlendMode::ColorBurn => sep(|b, s| {
            if b >= 1.0 {
                1.0
            } else if s <= 0.0 {
                0.0
            } else {
                1.0 - ((1.0 - b) / s).min(1.0)
            }
        }),
        BlendMode::HardLight => sep(hard_light),
        BlendMode::SoftLight => sep(|b, s| {
            if s <= 0.5 {
                b - (1.0 - 2.0 * s) * b * (1.0 - b)
            } else {
                let d = if b <= 0.25 {
                    ((16.0 * b - 12.0) * b + 4.0) * b
                } else {
                    b.sqrt()
                };
                b + (2.0 * s - 1.0) * (d - b)
            }
        }),
        BlendMode::Difference => sep(|b, s| (b - s).abs()),
        BlendMode::Exclusion => sep(|b, s| b + s - 2.0 * b * s),
        BlendMode::Hue => set_lum(set_sat(s, sat(b)), lum(b)),
        BlendMode::Saturation => set_lum(set_sat(b, sat(s)), lum(b)),
        BlendMode::Color => set_lum(s, lum(b)),
        BlendMode::Luminosity => set_lum(b, lum(s)),
    }
}

fn screen(b: f32, s: f32) -> f32 {
    b + s - b * s
}

fn hard_light(b: f32, s: f32) -> f32 {
    if s <= 0.5 {
        b * 2.0 * s
    } else {
        screen(b, 2.0 * s - 1.0)
    }
}

fn lum(c: [f32; 3]) -> f32 {
    0.3 * c[0] + 0.59 * c[1] + 0.11 * c[2]
}

fn clip_color(c: [f32; 3]) -> [f32; 3] {
    let l = lum(c);
    let n = c[0].min(c[1]).min(c[2]);
    let x = c[0].max(c[1]).max(c[2]);
    let mut c = c;
    if n < 0.0 && l - n > 0.0 {
        c = c.map(|v| l + (v - l) * l / (l - n));
    }
    if x > 1.0 && x - l > 0.0 {
        c = c.map(|v| l + (v - l) * (1.0 - l) / (x - l));
    }
    c
}

fn set_lum(c: [f32; 3], l: f32) -> [f32; 3] {
    let d = l - lum(c);
    clip_color(c.map(|v| v + d))
}

fn sat(c: [f32; 3]) -> f32 {
    c[0].max(c[1]).max(c[2]) - c[0].min(c[1]).min(c[2])
}

fn set_sat(c: [f32; 3], s: f32) -> [f32; 3] {
    let (mx, mn) = (c[0].max(c[1]).max(c[2]), c[0].min(c[1]).min(c[2]));
    if mx > mn {
        c.map(|v| (v - mn) * s / (mx - mn))
    } else {
        [0.0; 3]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Closed forms of the W3C formulas on opaque colours: multiply, screen, difference,
    /// exclusion, darken, lighten, and luminosity keeping the backdrop's hue.
    #[test]
    fn separable_modes_match_closed_forms() {
        let b = [0.2f32, 0.5, 0.8, 1.0];
        let s = [0.6f32, 0.4, 0.1, 1.0];
        let run = |mode| {
            let mut d = b;
            composite(&mut d, s, mode);
            d
        };
        let near = |x: [f32; 4], y: [f32; 3]| (0..3).all(|c| (x[c] - y[c]).abs() < 1e-6);
        assert!(near(run(BlendMode::Multiply), [0.12, 0.2, 0.08]));
        assert!(near(run(BlendMode::Screen), [0.68, 0.7, 0.82]));
        assert!(near(run(BlendMode::Difference), [0.4, 0.1, 0.7]));
        assert!(near(run(BlendMode::Exclusion), [0.56, 0.5, 0.74]));
        assert!(near(run(BlendMode::Darken), [0.2, 0.4, 0.1]));
        assert!(near(run(BlendMode::Lighten), [0.6, 0.5, 0.8]));
        // Luminosity: the result has the source's luminosity.
        let l = run(BlendMode::Luminosity);
        assert!((lum([l[0], l[1], l[2]]) - lum([s[0], s[1], s[2]])).abs() < 1e-5);
        // A transparent source leaves the backdrop; an empty backdrop takes the source.
        let mut d = b;
        composite(&mut d, [0.0; 4], BlendMode::Multiply);
        assert_eq!(d, b);
        let mut d = [0.0; 4];
        composite(&mut d, [0.3, 0.2, 0.1, 0.5], BlendMode::ColorBurn);
        assert!(near(d, [0.3, 0.2, 0.1]) && (d[3] - 0.5).abs() < 1e-6);
    }
}
