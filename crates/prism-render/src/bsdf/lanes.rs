//! The smooth BSDFs (diffuse and rough conductor) on sixteen lanes: [`Bsdf::eval_pdf`] and
//! [`Bsdf::sample`] with each lane doing the scalar code's operations in its order (branches
//! become selects), so that every lane's result is the scalar one, bit for bit.

// Plain index loops over the lanes are what the vectoriser turns into single instructions.
#![allow(clippy::needless_range_loop)]

use prism_math::lanes::{F16, M16, V16};
use std::f32::consts::PI;

use super::Bsdf;

/// Which of the smooth BSDFs a group of lanes holds (one kind per group).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum SmoothKind {
    /// [`Bsdf::Diffuse`].
    Diffuse,
    /// [`Bsdf::Conductor`].
    Conductor,
}

impl SmoothKind {
    /// The kind of `bsdf`, if it is a smooth BSDF these lanes handle.
    pub(crate) fn of(bsdf: &Bsdf) -> Option<SmoothKind> {
        match bsdf {
            Bsdf::Diffuse { .. } => Some(SmoothKind::Diffuse),
            Bsdf::Conductor { .. } => Some(SmoothKind::Conductor),
            _ => None,
        }
    }
}

/// Sixteen BSDFs of one [`SmoothKind`], their parameters side by side: a diffuse BSDF's
/// albedo in `color`; a conductor's roughness in `alpha`, its index in `color` and its
/// absorption in `k`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SmoothLanes {
    kind: SmoothKind,
    color: [F16; 3],
    alpha: F16,
    k: [F16; 3],
}

/// A sample drawn on lanes: the lanes that have one, and their directions, weights and
/// densities (as [`super::BsdfSample`], never a delta lobe).
pub(crate) struct LaneSample {
    /// Lanes with a sample.
    pub ok: M16,
    /// Sampled incident directions (local frame).
    pub wi: V16,
    /// `eval / pdf`, per channel.
    pub weight: [F16; 3],
    /// Solid-angle densities.
    pub pdf: F16,
}

impl SmoothLanes {
    /// Lanes of kind `kind`, their parameters still to be set ([`SmoothLanes::put`]).
    pub(crate) fn new(kind: SmoothKind) -> SmoothLanes {
        SmoothLanes {
            kind,
            color: [F16::default(); 3],
            alpha: F16::default(),
            k: [F16::default(); 3],
        }
    }

    /// Sets lane `lane` to `bsdf` (of this group's kind; another leaves the lane as it
    /// was).
    #[inline(always)]
    pub(crate) fn put(&mut self, lane: usize, bsdf: &Bsdf) {
        match *bsdf {
            Bsdf::Diffuse { albedo } => {
                self.color[0].0[lane] = albedo.r;
                self.color[1].0[lane] = albedo.g;
                self.color[2].0[lane] = albedo.b;
            }
            Bsdf::Conductor { alpha, eta, k } => {
                self.alpha.0[lane] = alpha;
                for (c, (e, k)) in [(eta.r, k.r), (eta.g, k.g), (eta.b, k.b)]
                    .into_iter()
                    .enumerate()
                {
                    self.color[c].0[lane] = e;
                    self.k[c].0[lane] = k;
                }
            }
            _ => {}
        }
    }

    /// [`Bsdf::eval_pdf`] on every lane: the BSDF times `|cos wi|`, and the density of
    /// sampling `wi`.
    #[inline(always)]
    pub(crate) fn eval_pdf(&self, wo: V16, wi: V16) -> ([F16; 3], F16) {
        let zero = F16::splat(0.0);
        let apart = (wo.z * wi.z).le(zero);
        let (wo, wi) = upper(wo, wi);
        let (f, pdf) = match self.kind {
            SmoothKind::Diffuse => {
                let scale = wi.z / F16::splat(PI);
                (
                    [
                        self.color[0] * scale,
                        self.color[1] * scale,
                        self.color[2] * scale,
                    ],
                    wi.z.max_num(zero) * F16::splat(std::f32::consts::FRAC_1_PI),
                )
            }
            SmoothKind::Conductor => self.conductor_eval_pdf(wo, wi),
        };
        (
            [
                F16::select(apart, zero, f[0]),
                F16::select(apart, zero, f[1]),
                F16::select(apart, zero, f[2]),
            ],
            F16::select(apart, zero, pdf),
        )
    }

    /// The conductor's branch of [`SmoothLanes::eval_pdf`], `wo` and `wi` in the upper
    /// hemisphere.
    #[inline(always)]
    fn conductor_eval_pdf(&self, wo: V16, wi: V16) -> ([F16; 3], F16) {
        let alpha = self.alpha;
        let h = (wo + wi).normalize();
        let d = beckmann_d(h, alpha);
        let g1_wo = smith_g1(wo, h, alpha);
        let g = g1_wo * smith_g1(wi, h, alpha);
        let cos = wi.dot(h);
        let denom = F16::splat(4.0) * wo.z;
        let scale = d * g / denom;
        let f = [
            fresnel_conductor(cos, self.color[0], self.k[0]) * scale,
            fresnel_conductor(cos, self.color[1], self.k[1]) * scale,
            fresnel_conductor(cos, self.color[2], self.k[2]) * scale,
        ];
        (f, g1_wo * d / denom)
    }

    /// [`Bsdf::sample`] on every lane, with `u2x, u2y` its `u2` (a smooth BSDF has one lobe:
    /// `u1` goes unused).
    #[inline(always)]
    pub(crate) fn sample(&self, wo: V16, u2x: F16, u2y: F16) -> LaneSample {
        let zero = F16::splat(0.0);
        let below = wo.z.lt(zero);
        let flip = |v: V16| V16 {
            x: v.x,
            y: v.y,
            z: F16::select(below, -v.z, v.z),
        };
        let some = !wo.z.eq(zero);
        match self.kind {
            SmoothKind::Diffuse => {
                let d = prism_math::warp::cosine_hemisphere_lanes(u2x, u2y);
                LaneSample {
                    ok: some & !d.z.le(zero),
                    wi: flip(d),
                    weight: self.color,
                    pdf: d.z.max_num(zero) * F16::splat(std::f32::consts::FRAC_1_PI),
                }
            }
            SmoothKind::Conductor => {
                let wo_up = flip(wo);
                let h = sample_beckmann_visible(wo_up, self.alpha, u2x, u2y);
                let cos = wo_up.dot(h);
                let wi = h * (F16::splat(2.0) * cos) - wo_up;
                // As the scalar tests `wi.z <= 0` and `wo.h <= 0`: a NaN goes on.
                let ok = some & !wi.z.le(zero) & !cos.le(zero);
                let wi = flip(wi);
                let (f, pdf) = self.eval_pdf(wo, wi);
                let inv = F16::splat(1.0) / pdf;
                LaneSample {
                    ok: ok & !pdf.le(zero),
                    wi,
                    weight: [f[0] * inv, f[1] * inv, f[2] * inv],
                    pdf,
                }
            }
        }
    }
}

/// `upper` on lanes: both directions mirrored where `wo` is below the surface.
#[inline(always)]
fn upper(wo: V16, wi: V16) -> (V16, V16) {
    let below = wo.z.lt(F16::splat(0.0));
    (
        V16 {
            z: F16::select(below, -wo.z, wo.z),
            ..wo
        },
        V16 {
            z: F16::select(below, -wi.z, wi.z),
            ..wi
        },
    )
}

/// `f32::clamp` lane by lane (a NaN stays NaN).
#[inline(always)]
fn clamp(x: F16, lo: F16, hi: F16) -> F16 {
    let x = F16::select(x.lt(lo), lo, x);
    F16::select(hi.lt(x), hi, x)
}

/// `beckmann_d` lane by lane.
#[inline(always)]
fn beckmann_d(h: V16, alpha: F16) -> F16 {
    let c2 = h.z * h.z;
    let tan2 = (F16::splat(1.0) - c2) / c2;
    let d = (-tan2 / (alpha * alpha)).exp() / (F16::splat(PI) * alpha * alpha * c2 * c2);
    F16::select(c2.le(F16::splat(0.0)), F16::splat(0.0), d)
}

/// `smith_g1` lane by lane.
#[inline(always)]
fn smith_g1(v: V16, h: V16, alpha: F16) -> F16 {
    let (zero, one) = (F16::splat(0.0), F16::splat(1.0));
    let tan = (one - v.z * v.z).max_num(zero).sqrt() / v.z;
    let a = one / (alpha * tan);
    let rational = (F16::splat(3.535) * a + F16::splat(2.181) * a * a)
        / (one + F16::splat(2.276) * a + F16::splat(2.577) * a * a);
    let g = F16::select(F16::splat(1.6).le(a), one, rational);
    let g = F16::select(tan.eq(zero), one, g);
    F16::select((v.dot(h) * v.z).le(zero), zero, g)
}

/// `fresnel_conductor` of one channel, lane by lane.
#[inline(always)]
fn fresnel_conductor(cos: F16, eta: F16, k: F16) -> F16 {
    let (zero, one) = (F16::splat(0.0), F16::splat(1.0));
    let c = clamp(cos, zero, one);
    let c2 = c * c;
    let s2 = one - c2;
    let t0 = eta * eta - k * k - s2;
    let a2b2 = (t0 * t0 + F16::splat(4.0) * eta * eta * k * k)
        .max_num(zero)
        .sqrt();
    let t1 = a2b2 + c2;
    let a = (F16::splat(0.5) * (a2b2 + t0)).max_num(zero).sqrt();
    let t2 = F16::splat(2.0) * c * a;
    let rs = (t1 - t2) / (t1 + t2);
    let t3 = c2 * a2b2 + s2 * s2;
    let t4 = t2 * s2;
    let rp = rs * (t3 - t4) / (t3 + t4);
    F16::splat(0.5) * (rs + rp)
}

/// `sample_beckmann_visible` lane by lane.
#[inline(always)]
fn sample_beckmann_visible(wo: V16, alpha: F16, ux: F16, uy: F16) -> V16 {
    let stretched = V16 {
        x: alpha * wo.x,
        y: alpha * wo.y,
        z: wo.z,
    }
    .normalize();
    let (sx, sy) = beckmann_visible_slopes(stretched.z, ux, uy);
    let r = (stretched.x * stretched.x + stretched.y * stretched.y).sqrt();
    let round = F16::splat(0.0).lt(r);
    let cos_phi = F16::select(round, stretched.x / r, F16::splat(1.0));
    let sin_phi = F16::select(round, stretched.y / r, F16::splat(0.0));
    let tx = alpha * (cos_phi * sx - sin_phi * sy);
    let ty = alpha * (sin_phi * sx + cos_phi * sy);
    V16 {
        x: -tx,
        y: -ty,
        z: F16::splat(1.0),
    }
    .normalize()
}

/// `beckmann_visible_slopes` lane by lane, on the best instructions the processor has.
fn beckmann_visible_slopes(cos: F16, ux: F16, uy: F16) -> (F16, F16) {
    #[cfg(target_arch = "x86_64")]
    {
        if prism_math::Isa::avx512() {
            // SAFETY: the processor has AVX-512F.
            return unsafe { slopes_avx512(cos, ux, uy) };
        }
        if prism_math::Isa::avx2() {
            // SAFETY: the processor has AVX2.
            return unsafe { slopes_avx2(cos, ux, uy) };
        }
    }
    slopes(cos, ux, uy)
}

/// [`slopes`] compiled for AVX-512.
///
/// # Safety
/// The processor must support AVX-512F.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
unsafe fn slopes_avx512(cos: F16, ux: F16, uy: F16) -> (F16, F16) {
    slopes(cos, ux, uy)
}

/// [`slopes`] compiled for AVX2.
///
/// # Safety
/// The processor must support AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn slopes_avx2(cos: F16, ux: F16, uy: F16) -> (F16, F16) {
    slopes(cos, ux, uy)
}

/// `beckmann_visible_slopes` lane by lane (both of its cases computed, then chosen).
#[inline(always)]
fn slopes(cos: F16, ux: F16, uy: F16) -> (F16, F16) {
    let one = F16::splat(1.0);
    let (lo, hi) = (F16::splat(1e-6), F16::splat(1.0 - 1e-6));
    let y = erf_inv(F16::splat(2.0) * clamp(uy, lo, hi) - one);
    let ux = clamp(ux, lo, hi);
    let from_above = erf_inv(F16::splat(2.0) * ux - one);
    let sin = (one - cos * cos).max_num(F16::splat(0.0)).sqrt();
    let tan = sin / cos;
    let cot = cos / sin;
    let top = erf(cot);
    let inv_sqrt_pi = F16::splat(1.0 / PI.sqrt());
    let norm = one / (one + top + inv_sqrt_pi * tan * (-cot * cot).exp());
    let theta = cos.acos();
    let fit = one
        + theta * (F16::splat(-0.876) + theta * (F16::splat(0.4265) - F16::splat(0.0594) * theta));
    let mut b = top - (one + top) * (fit * (one - ux).ln()).exp();
    let b_lo = F16::splat(-1.0 + 1e-6);
    let b_hi = top.min_num(F16::splat(1.0 - 1e-6));
    for _ in 0..3 {
        let s = erf_inv(b);
        let value = norm * (one + b + inv_sqrt_pi * tan * (-s * s).exp()) - ux;
        let slope = norm * (one - s * tan);
        let stepped = clamp(b - value / slope, b_lo, b_hi);
        b = F16::select(F16::splat(1e-12).lt(slope.abs()), stepped, b);
    }
    let x = F16::select(F16::splat(0.9999).lt(cos), from_above, erf_inv(b));
    (x, y)
}

/// `erf` lane by lane.
#[inline(always)]
fn erf(x: F16) -> F16 {
    let a = x.abs();
    let t = F16::splat(1.0) / (F16::splat(1.0) + F16::splat(0.327_591_1) * a);
    let poly = t
        * (F16::splat(0.254_829_6)
            + t * (F16::splat(-0.284_496_74)
                + t * (F16::splat(1.421_413_7)
                    + t * (F16::splat(-1.453_152) + t * F16::splat(1.061_405_4)))));
    (F16::splat(1.0) - poly * (-a * a).exp()).copysign(x)
}

/// `erf_inv` lane by lane (both of its ranges computed, then chosen).
#[inline(always)]
fn erf_inv(x: F16) -> F16 {
    let one = F16::splat(1.0);
    let w = -((one - x) * (one + x)).ln();
    let near = w - F16::splat(2.5);
    let mut p_near = F16::splat(super::ERF_INV_NEAR_LEAD);
    for c in super::ERF_INV_NEAR {
        p_near = F16::splat(c) + p_near * near;
    }
    let far = w.sqrt() - F16::splat(3.0);
    let mut p_far = F16::splat(super::ERF_INV_FAR_LEAD);
    for c in super::ERF_INV_FAR {
        p_far = F16::splat(c) + p_far * far;
    }
    F16::select(w.lt(F16::splat(5.0)), p_near, p_far) * x
}

/// Lane `lane` of `v`.
#[cfg(test)]
fn lane(v: &V16, lane: usize) -> prism_math::Vec3 {
    prism_math::Vec3::new(v.x.0[lane], v.y.0[lane], v.z.0[lane])
}

#[cfg(test)]
mod tests {
    use super::*;
    use prism_math::lanes::LANES;
    use prism_math::{Pcg32, Rgb, Vec2, Vec3};

    /// Random directions on the sphere, with a few on the horizon and at the poles.
    fn direction(rng: &mut Pcg32, i: usize) -> Vec3 {
        match i % 23 {
            0 => Vec3::Z,
            1 => -Vec3::Z,
            2 => Vec3::new(1.0, 0.0, 0.0),
            3 => Vec3::new(0.6, 0.0, 1e-7).normalize(),
            _ => prism_math::warp::uniform_sphere(Vec2::new(rng.next_f32(), rng.next_f32())),
        }
    }

    fn bsdfs(rng: &mut Pcg32) -> [Bsdf; 2] {
        [
            Bsdf::Diffuse {
                albedo: Rgb::new(rng.next_f32(), 0.5, 0.25),
            },
            Bsdf::Conductor {
                alpha: [0.05, 0.2, 0.5, 1.0][(rng.next_u32() % 4) as usize],
                eta: Rgb::new(0.2, 0.92, 1.1),
                k: Rgb::new(3.9, 2.45, 2.14),
            },
        ]
    }

    fn put_v(v: &mut V16, lane: usize, p: Vec3) {
        v.x.0[lane] = p.x;
        v.y.0[lane] = p.y;
        v.z.0[lane] = p.z;
    }

    fn same(a: f32, b: f32) -> bool {
        a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
    }

    /// Property: every lane's `eval_pdf` and `sample` equal the scalar `Bsdf`'s bit for bit
    /// (directions all over the sphere, the poles and the horizon included; conductors of
    /// several roughnesses, each lane its own parameters).
    #[test]
    fn lanes_equal_the_scalar_bsdfs_bit_for_bit() {
        let mut rng = Pcg32::new(5, 9);
        for round in 0..400 {
            let kind = [SmoothKind::Diffuse, SmoothKind::Conductor][round % 2];
            let mut lanes = SmoothLanes::new(kind);
            let (mut wo, mut wi) = (V16::default(), V16::default());
            let mut scalar = Vec::new();
            let (mut ux, mut uy) = (F16::default(), F16::default());
            for l in 0..LANES {
                let b = bsdfs(&mut rng)[round % 2];
                lanes.put(l, &b);
                let (o, i) = (direction(&mut rng, l + round), direction(&mut rng, l));
                put_v(&mut wo, l, o);
                put_v(&mut wi, l, i);
                let u = Vec2::new(rng.next_f32(), rng.next_f32());
                ux.0[l] = u.x;
                uy.0[l] = u.y;
                scalar.push((b, o, i, u));
            }
            let (f, pdf) = lanes.eval_pdf(wo, wi);
            let s = lanes.sample(wo, ux, uy);
            for (l, (b, o, i, u)) in scalar.into_iter().enumerate() {
                let (sf, spdf) = b.eval_pdf(o, i);
                let what = format!("{b:?} wo {o} wi {i}");
                assert!(
                    same(f[0].0[l], sf.r) && same(f[1].0[l], sf.g),
                    "eval {what}"
                );
                assert!(same(f[2].0[l], sf.b) && same(pdf.0[l], spdf), "pdf {what}");
                match b.sample(o, 0.5, u) {
                    Some(ss) => {
                        assert!(s.ok.get(l), "sample missing: {what} u {u}");
                        let w = lane(&s.wi, l);
                        assert!(same(w.x, ss.wi.x) && same(w.y, ss.wi.y), "wi {what}");
                        assert!(same(w.z, ss.wi.z) && same(s.pdf.0[l], ss.pdf), "{what}");
                        let sw = [ss.weight.r, ss.weight.g, ss.weight.b];
                        for c in 0..3 {
                            assert!(same(s.weight[c].0[l], sw[c]), "weight {what}");
                        }
                    }
                    None => assert!(!s.ok.get(l), "sample kept: {what} u {u}"),
                }
            }
        }
    }
}
