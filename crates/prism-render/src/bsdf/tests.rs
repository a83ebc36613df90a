//! Tests of the BSDFs: sampling against the pdf by chi-square, closed forms, and glass.

use super::*;
use prism_math::Pcg32;

pub(super) fn dir(theta_deg: f32, phi: f32) -> Vec3 {
    let t = theta_deg.to_radians();
    Vec3::new(t.sin() * phi.cos(), t.sin() * phi.sin(), t.cos())
}

/// Oracle: chi-square test of `sample` against the integral of `pdf` over (cos theta, phi)
/// cells of the sphere, for several outgoing directions; then `weight == eval / pdf`.
pub(super) fn check_sampling(b: &Bsdf, wo: Vec3) {
    let (nc, np) = (20usize, 40usize);
    let n = 200_000;
    let mut rng = Pcg32::new(11, 7);
    let mut observed = vec![0.0; nc * np];
    let cell = |w: Vec3| -> usize {
        let c = (((w.z + 1.0) / 2.0 * nc as f32) as usize).min(nc - 1);
        let p = ((w.y.atan2(w.x) + PI) / (2.0 * PI) * np as f32) as usize;
        c * np + p.min(np - 1)
    };
    for _ in 0..n {
        let u1 = rng.next_f32();
        let u2 = Vec2::new(rng.next_f32(), rng.next_f32());
        if let Some(s) = b.sample(wo, u1, u2) {
            assert!((s.wi.length() - 1.0).abs() < 1e-3);
            let e = b.eval(wo, s.wi);
            let p = b.pdf(wo, s.wi);
            assert!(
                (p - s.pdf).abs() <= 1e-3 * p.max(1.0),
                "pdf {p} vs {}",
                s.pdf
            );
            for (x, y) in [(e.r, s.weight.r), (e.g, s.weight.g), (e.b, s.weight.b)] {
                assert!(
                    (x / p - y).abs() <= 1e-3 * y.abs().max(1.0),
                    "{x}/{p} vs {y}"
                );
            }
            observed[cell(s.wi)] += 1.0;
        }
    }
    // Expected counts: the pdf integrated over each cell by a 48x48 midpoint rule.
    let mut expected = vec![0.0; nc * np];
    let sub = 48;
    for c in 0..nc {
        for p in 0..np {
            let mut acc = 0.0;
            for i in 0..sub {
                for j in 0..sub {
                    let z = -1.0 + 2.0 * (c as f32 + (i as f32 + 0.5) / sub as f32) / nc as f32;
                    let phi =
                        -PI + 2.0 * PI * (p as f32 + (j as f32 + 0.5) / sub as f32) / np as f32;
                    let r = (1.0 - z * z).max(0.0).sqrt();
                    acc += b.pdf(wo, Vec3::new(r * phi.cos(), r * phi.sin(), z));
                }
            }
            let area = (2.0 / nc as f32) * (2.0 * PI / np as f32);
            expected[c * np + p] = f64::from(acc / (sub * sub) as f32 * area) * n as f64;
        }
    }
    let (stat, crit) = prism_testkit::chi_square(&observed, &expected);
    assert!(stat < crit, "{b:?} wo={wo}: chi-square {stat} > {crit}");
}

#[test]
fn diffuse_sampling_matches_its_pdf() {
    let b = Bsdf::Diffuse {
        albedo: Rgb::new(0.5, 0.6, 0.7),
    };
    for wo in [dir(10.0, 0.3), dir(70.0, 2.0), -dir(30.0, 1.0)] {
        check_sampling(&b, wo);
    }
}

#[test]
fn conductor_sampling_matches_its_pdf() {
    for alpha in [0.1, 0.25, 0.6] {
        let b = Bsdf::Conductor {
            alpha,
            eta: Rgb::new(0.2, 0.9, 1.1),
            k: Rgb::new(3.9, 2.4, 2.2),
        };
        for wo in [
            dir(5.0, 0.0),
            dir(45.0, 1.0),
            dir(80.0, -2.0),
            -dir(40.0, 0.5),
        ] {
            check_sampling(&b, wo);
        }
    }
}

/// Closed forms: a white Lambertian reflects everything (the integral of eval over the
/// hemisphere is 1); a conductor is reciprocal and reflects at most everything; the Fresnel
/// terms at normal incidence equal ((n-1)/(n+1))^2 and ((n-1)^2+k^2)/((n+1)^2+k^2).
#[test]
fn closed_forms() {
    let white = Bsdf::Diffuse { albedo: Rgb::WHITE };
    let wo = dir(30.0, 0.0);
    let mut rng = Pcg32::new(1, 2);
    let n = 100_000;
    let mut total = 0.0;
    for _ in 0..n {
        let wi = prism_math::warp::uniform_hemisphere(Vec2::new(rng.next_f32(), rng.next_f32()));
        total += white.eval(wo, wi).r / prism_math::warp::uniform_hemisphere_pdf();
    }
    assert!(
        (total / n as f32 - 1.0).abs() < 0.01,
        "{}",
        total / n as f32
    );
    let c = Bsdf::Conductor {
        alpha: 0.3,
        eta: Rgb::splat(0.2),
        k: Rgb::splat(3.0),
    };
    let (a, b) = (dir(20.0, 0.1), dir(50.0, 2.5));
    assert!((c.eval(a, b).r / b.z - c.eval(b, a).r / a.z).abs() < 1e-5);
    let f = fresnel_dielectric(1.0, 1.5);
    assert!((f - 0.04).abs() < 1e-6);
    assert!((fresnel_dielectric(-1.0, 1.5) - 0.04).abs() < 1e-6);
    assert_eq!(fresnel_dielectric(-0.2, 1.5), 1.0); // total internal reflection
    let fc = fresnel_conductor(1.0, Rgb::splat(0.2), Rgb::splat(3.0));
    assert!((fc.r - (0.64 + 9.0) / (1.44 + 9.0)).abs() < 1e-5);
}

/// Property: glass reflects with probability F and refracts by Snell's law with the radiance
/// scale (eta_o / eta_i)^2; refraction back out undoes it.
#[test]
fn glass_sampling() {
    let g = Bsdf::Glass {
        reflectance: Rgb::WHITE,
        transmittance: Rgb::WHITE,
        ior: 1.5,
    };
    let wo = dir(40.0, 0.7);
    let f = fresnel_dielectric(wo.z, 1.5);
    let r = g.sample(wo, f * 0.5, Vec2::ZERO).unwrap();
    assert!(r.delta && (r.pdf - f).abs() < 1e-6 && r.wi.z > 0.0);
    let t = g.sample(wo, (f + 1.0) * 0.5, Vec2::ZERO).unwrap();
    assert!(t.wi.z < 0.0 && (t.pdf - (1.0 - f)).abs() < 1e-6);
    let sin_i = (1.0 - t.wi.z * t.wi.z).sqrt();
    let sin_o = (1.0 - wo.z * wo.z).sqrt();
    assert!((sin_o - 1.5 * sin_i).abs() < 1e-5);
    assert!((t.weight.r - 1.0 / 2.25).abs() < 1e-5);
    let back = g.sample(t.wi, 0.999, Vec2::ZERO).unwrap();
    assert!((back.wi - wo).length() < 1e-4 && (back.weight.r - 2.25).abs() < 1e-4);
}

/// Closed forms: erf at tabulated points (to 2e-7), and erf_inv inverts it.
#[test]
fn erf_and_its_inverse() {
    for (x, want) in [
        (0.0, 0.0),
        (0.5, 0.520_499_9),
        (1.0, 0.842_700_8),
        (2.0, 0.995_322_3),
        (-1.5, -0.966_105_1),
    ] {
        assert!((erf(x) - want).abs() < 2e-7, "erf({x}) = {}", erf(x));
    }
    for x in [-2.5f32, -1.0, -0.3, 0.0, 0.2, 0.9, 1.7, 2.6] {
        assert!((erf_inv(erf(x)) - x).abs() < 2e-3 * x.abs().max(1.0), "{x}");
    }
}

/// Property of visible-normal sampling: the weight `eval / pdf` is `F G1(wi)`, never
/// above the Fresnel term (so at most 1 for a conductor that reflects at most everything).
#[test]
fn visible_normal_weights_are_bounded() {
    let c = Bsdf::Conductor {
        alpha: 0.4,
        eta: Rgb::new(0.2, 0.9, 1.1),
        k: Rgb::new(3.9, 2.4, 2.2),
    };
    let mut rng = Pcg32::new(3, 9);
    for theta in [0.0, 20.0, 60.0, 85.0] {
        let wo = dir(theta, 0.4);
        for _ in 0..10_000 {
            let u = Vec2::new(rng.next_f32(), rng.next_f32());
            if let Some(s) = c.sample(wo, 0.5, u) {
                let h = (wo + s.wi).normalize();
                let f = fresnel_conductor(
                    s.wi.dot(h),
                    Rgb::new(0.2, 0.9, 1.1),
                    Rgb::new(3.9, 2.4, 2.2),
                );
                assert!(
                    s.weight.r <= f.r * 1.001 && s.weight.g <= f.g * 1.001,
                    "{theta}"
                );
            }
        }
    }
}

/// Oracle: `eval` and `pdf` called apart. `eval_pdf` gives both bit for bit, for every BSDF,
/// on random pairs of directions on both sides of the surface.
#[test]
fn eval_pdf_equals_eval_and_pdf() {
    let bsdfs = [
        Bsdf::Diffuse {
            albedo: Rgb::new(0.7, 0.5, 0.3),
        },
        Bsdf::Conductor {
            alpha: 0.3,
            eta: Rgb::new(0.2, 0.92, 1.1),
            k: Rgb::new(3.9, 2.45, 2.14),
        },
        Bsdf::Conductor {
            alpha: 0.05,
            eta: Rgb::new(1.5, 1.5, 1.5),
            k: Rgb::new(0.0, 0.5, 1.0),
        },
        Bsdf::Mirror {
            reflectance: Rgb::WHITE,
        },
        Bsdf::Black,
    ];
    let mut rng = Pcg32::new(3, 9);
    let mut unit = || {
        let z = 1.0 - 2.0 * rng.next_f32();
        let phi = 2.0 * PI * rng.next_f32();
        let r = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new(r * phi.cos(), r * phi.sin(), z)
    };
    for b in &bsdfs {
        for _ in 0..2000 {
            let (wo, wi) = (unit(), unit());
            let (f, p) = b.eval_pdf(wo, wi);
            let e = b.eval(wo, wi);
            assert_eq!(
                [f.r, f.g, f.b].map(f32::to_bits),
                [e.r, e.g, e.b].map(f32::to_bits),
                "{b:?}"
            );
            assert_eq!(p.to_bits(), b.pdf(wo, wi).to_bits(), "{b:?}");
        }
    }
}

/// Mitsuba's smooth plastic, against closed forms and properties: a diffuse sample's weight
/// is its `eval / pdf`; the lobes' chances add to one; the mirror lobe's expected weight is
/// the Fresnel reflectance at `wo`; and the hemispherical diffuse Fresnel fits give the
/// published Fdr(1.5) = 0.0918 and, inside, the value reciprocity ties to it.
#[test]
fn plastic_is_mitsubas_smooth_plastic() {
    assert!(
        (fresnel_diffuse_reflectance(1.5) - 0.0918).abs() < 5e-4,
        "{}",
        fresnel_diffuse_reflectance(1.5)
    );
    // Inside and outside are tied by reciprocity: Fdr(1/n) = 1 - (1 - Fdr(n)) / n^2.
    let inside = 1.0 - (1.0 - fresnel_diffuse_reflectance(1.5)) / 2.25;
    assert!(
        (fresnel_diffuse_reflectance(1.0 / 1.5) - inside).abs() < 1e-3,
        "{inside}"
    );
    let b = Bsdf::from_material(&prism_scene::Material::Plastic {
        diffuse: Rgb::new(0.8, 0.4, 0.2),
        specular: Rgb::splat(1.0),
        eta: 1.49,
        texture: None,
        nonlinear: false,
    });
    let mut rng = Pcg32::new(11, 3);
    let wo = Vec3::new(0.3, -0.2, 0.9).normalize();
    let (mut mirror, mut n) = (0.0f64, 0);
    // The lobe choice stratified: the mirror's share is exact up to one sample.
    for i in 0..20_000 {
        let u1 = (i as f32 + 0.5) / 20_000.0;
        let u2 = Vec2::new(rng.next_f32(), rng.next_f32());
        let Some(s) = b.sample(wo, u1, u2) else {
            continue;
        };
        n += 1;
        if s.delta {
            mirror += f64::from(s.weight.r);
        } else {
            let e = b.eval(wo, s.wi);
            assert!(
                ((e.g / s.pdf) / s.weight.g - 1.0).abs() < 1e-4,
                "{e:?} {s:?}"
            );
            assert!((b.pdf(wo, s.wi) / s.pdf - 1.0).abs() < 1e-5);
        }
    }
    let f = f64::from(fresnel_dielectric(wo.z, 1.49));
    assert!(
        (mirror / f64::from(n) / f - 1.0).abs() < 0.01,
        "{} vs {f}",
        mirror / f64::from(n)
    );
}

/// Closed form of Mitsuba's thin dielectric: it reflects `2F / (1 + F)` of the light (the
/// pane's inner reflections summed) as a mirror and passes the rest straight through.
#[test]
fn thin_dielectric_reflects_2f_over_1_plus_f() {
    let b = Bsdf::from_material(&prism_scene::Material::ThinDielectric {
        reflectance: Rgb::splat(1.0),
        transmittance: Rgb::splat(1.0),
        ior: 1.5,
    });
    let wo = Vec3::new(0.4, 0.1, 0.6).normalize();
    let f = fresnel_dielectric(wo.z, 1.5);
    let r = 2.0 * f / (1.0 + f);
    let n = 10_000;
    let mut reflected = 0;
    for i in 0..n {
        let s = b
            .sample(wo, (i as f32 + 0.5) / n as f32, Vec2::ZERO)
            .unwrap();
        assert!(s.delta && s.weight == Rgb::splat(1.0));
        if s.wi.z > 0.0 {
            reflected += 1;
            assert!((s.wi - Vec3::new(-wo.x, -wo.y, wo.z)).length() < 1e-6);
        } else {
            assert!((s.wi + wo).length() < 1e-6, "straight through");
        }
    }
    assert!(
        (reflected as f32 / n as f32 - r).abs() < 2e-4,
        "{reflected} vs {r}"
    );
    assert!(!b.two_sided() && !b.is_smooth());
}

/// Closed form (Mitsuba's two plastic models): with `nonlinear`, a plastic's diffuse lobe
/// at a direction pair is the linear model's times `(1 - Fdr) / (1 - albedo Fdr)` per
/// channel, the same for a white base and darker for a coloured one.
#[test]
fn nonlinear_plastics_shift_colour_by_internal_scattering() {
    let plastic = |diffuse: Rgb, nonlinear: bool| {
        Bsdf::from_material(&prism_scene::Material::Plastic {
            diffuse,
            specular: Rgb::splat(1.0),
            eta: 1.5,
            texture: None,
            nonlinear,
        })
    };
    let (wo, wi) = (
        Vec3::new(0.3, -0.2, 0.9).normalize(),
        Vec3::new(-0.4, 0.1, 0.8).normalize(),
    );
    let fdr = fresnel_diffuse_reflectance(1.0 / 1.5);
    let albedo = Rgb::new(0.8, 0.4, 0.2);
    let (linear, shifted) = (
        plastic(albedo, false).eval(wo, wi),
        plastic(albedo, true).eval(wo, wi),
    );
    for (l, s, a) in [
        (linear.r, shifted.r, albedo.r),
        (linear.g, shifted.g, albedo.g),
        (linear.b, shifted.b, albedo.b),
    ] {
        let want = l * (1.0 - fdr) / (1.0 - a * fdr);
        assert!((s - want).abs() <= 1e-6 * want, "{s} vs {want}");
        assert!(s < l);
    }
    let white = (
        plastic(Rgb::WHITE, false).eval(wo, wi),
        plastic(Rgb::WHITE, true).eval(wo, wi),
    );
    assert!((white.0.r - white.1.r).abs() <= 1e-6 * white.0.r);
}
