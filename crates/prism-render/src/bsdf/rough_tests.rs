//! Tests of the microfacet distributions and the rough BSDFs: normalisation by quadrature,
//! sampling against the pdf by chi-square, and the smooth limit's closed forms.

use super::tests::{check_sampling, dir};
use super::*;
use prism_math::Pcg32;
use prism_scene::MicrofacetKind;

fn distr(kind: MicrofacetKind, alpha_u: f32, alpha_v: f32) -> Microfacet {
    Microfacet {
        kind,
        alpha_u,
        alpha_v,
    }
}

/// The integral of `f` over the upper hemisphere by a midpoint rule in (cos theta, phi).
fn hemisphere_integral(f: impl Fn(Vec3) -> f64) -> f64 {
    let (nz, np) = (2000, 400);
    let mut total = 0.0;
    for i in 0..nz {
        let z = (i as f64 + 0.5) / nz as f64;
        let r = (1.0 - z * z).sqrt();
        for j in 0..np {
            let phi = 2.0 * std::f64::consts::PI * (j as f64 + 0.5) / np as f64;
            total += f(Vec3::new(
                (r * phi.cos()) as f32,
                (r * phi.sin()) as f32,
                z as f32,
            ));
        }
    }
    total * 2.0 * std::f64::consts::PI / (nz * np) as f64
}

/// Closed forms: the projected area of the microfacets is the macro-surface's,
/// `∫ D(m) cos(m) dm = 1`, and the visible normals' density integrates to one (exactly for
/// GGX's Smith term, within Walter's fit for Beckmann).
#[test]
fn distributions_are_normalised() {
    for kind in [MicrofacetKind::Beckmann, MicrofacetKind::Ggx] {
        for (au, av) in [(0.2, 0.2), (0.5, 0.5), (0.15, 0.6)] {
            let d = distr(kind, au, av);
            let area = hemisphere_integral(|m| f64::from(d.d(m) * m.z));
            assert!((area - 1.0).abs() < 2e-3, "{kind:?} {au} {av}: {area}");
            for theta in [0.0, 45.0, 80.0] {
                let v = dir(theta, 0.7);
                let visible = hemisphere_integral(|m| f64::from(d.pdf_visible(v, m)));
                let tolerance = if kind == MicrofacetKind::Ggx {
                    3e-3
                } else {
                    1e-2
                };
                assert!(
                    (visible - 1.0).abs() < tolerance,
                    "{kind:?} {au} {av} {theta}: {visible}"
                );
            }
        }
    }
}

/// Oracle: chi-square of the rough conductor's and rough dielectric's sampling against their
/// pdfs, both distributions, isotropic and anisotropic, from outside and from inside.
#[test]
fn rough_sampling_matches_its_pdf() {
    for kind in [MicrofacetKind::Beckmann, MicrofacetKind::Ggx] {
        for (au, av) in [(0.3, 0.3), (0.2, 0.6)] {
            let c = Bsdf::RoughConductor {
                distr: distr(kind, au, av),
                eta: Rgb::new(0.2, 0.9, 1.1),
                k: Rgb::new(3.9, 2.4, 2.2),
                specular: Rgb::new(1.0, 0.8, 0.6),
            };
            for wo in [dir(10.0, 0.0), dir(70.0, 1.0), -dir(40.0, 0.5)] {
                check_sampling(&c, wo);
            }
            let g = Bsdf::RoughDielectric {
                distr: distr(kind, au, av),
                reflectance: Rgb::WHITE,
                transmittance: Rgb::new(0.9, 0.8, 0.7),
                ior: 1.5,
            };
            for wo in [
                dir(20.0, 0.3),
                dir(75.0, 2.0),
                -dir(30.0, 1.0),
                -dir(60.0, 1.0),
            ] {
                check_sampling(&g, wo);
            }
        }
    }
}

/// Closed form of the smooth limit: at roughness 1e-3 a rough dielectric reflects the
/// Fresnel share `F` and passes `(1 - F) / eta^2` of radiance, as smooth glass does.
#[test]
fn rough_dielectric_tends_to_smooth_glass() {
    let ior = 1.5;
    for kind in [MicrofacetKind::Beckmann, MicrofacetKind::Ggx] {
        let g = Bsdf::RoughDielectric {
            distr: distr(kind, 1e-3, 1e-3),
            reflectance: Rgb::WHITE,
            transmittance: Rgb::WHITE,
            ior,
        };
        for wo in [dir(30.0, 0.2), -dir(20.0, 1.0)] {
            let mut rng = Pcg32::new(5, 1);
            let (mut reflected, mut passed) = (0.0f64, 0.0f64);
            let n = 200_000;
            for _ in 0..n {
                let u = Vec2::new(rng.next_f32(), rng.next_f32());
                if let Some(s) = g.sample(wo, rng.next_f32(), u) {
                    if s.wi.z * wo.z > 0.0 {
                        reflected += f64::from(s.weight.r);
                    } else {
                        passed += f64::from(s.weight.r);
                    }
                }
            }
            let f = f64::from(fresnel_dielectric(wo.z, ior));
            let eta = if wo.z > 0.0 {
                f64::from(ior)
            } else {
                1.0 / f64::from(ior)
            };
            let (r, t) = (reflected / n as f64, passed / n as f64);
            assert!(
                (r - f).abs() < 4e-3,
                "{kind:?} {wo}: reflected {r} vs F {f}"
            );
            let want = (1.0 - f) / (eta * eta);
            assert!(
                (t - want).abs() < 4e-3,
                "{kind:?} {wo}: passed {t} vs {want}"
            );
        }
    }
}

/// Property: a rough conductor is reciprocal, `f(wo, wi) = f(wi, wo)`, and `eval_pdf` equals
/// `eval` and `pdf` bit for bit for the rough BSDFs on both sides.
#[test]
fn rough_bsdfs_are_reciprocal_and_consistent() {
    let c = Bsdf::RoughConductor {
        distr: distr(MicrofacetKind::Ggx, 0.2, 0.5),
        eta: Rgb::splat(0.3),
        k: Rgb::splat(2.0),
        specular: Rgb::WHITE,
    };
    let g = Bsdf::RoughDielectric {
        distr: distr(MicrofacetKind::Beckmann, 0.3, 0.3),
        reflectance: Rgb::WHITE,
        transmittance: Rgb::WHITE,
        ior: 1.33,
    };
    let mut rng = Pcg32::new(8, 2);
    let mut unit = || {
        let z = 1.0 - 2.0 * rng.next_f32();
        let phi = 2.0 * PI * rng.next_f32();
        let r = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new(r * phi.cos(), r * phi.sin(), z)
    };
    for _ in 0..2000 {
        let (a, b) = (unit(), unit());
        if a.z * b.z > 0.0 {
            let (x, y) = (c.eval(a, b).r / b.z.abs(), c.eval(b, a).r / a.z.abs());
            assert!((x - y).abs() <= 1e-4 * x.max(1.0), "{x} {y}");
        }
        for bsdf in [c, g] {
            let (f, p) = bsdf.eval_pdf(a, b);
            assert_eq!(f.r.to_bits(), bsdf.eval(a, b).r.to_bits());
            assert_eq!(p.to_bits(), bsdf.pdf(a, b).to_bits());
        }
    }
}

/// Oracle: chi-square of Mitsuba's rough plastic's sampling against its pdf, both
/// distributions, from above and below.
#[test]
fn rough_plastic_sampling_matches_its_pdf() {
    for kind in [MicrofacetKind::Beckmann, MicrofacetKind::Ggx] {
        let b = Bsdf::from_material(&prism_scene::Material::RoughPlastic {
            roughness: prism_scene::Roughness {
                kind,
                alpha_u: 0.3,
                alpha_v: 0.3,
            },
            diffuse: Rgb::new(0.6, 0.3, 0.2),
            specular: Rgb::WHITE,
            eta: 1.5,
            texture: None,
            nonlinear: false,
        });
        for wo in [dir(15.0, 0.3), dir(70.0, 1.0), -dir(40.0, 2.0)] {
            check_sampling(&b, wo);
        }
    }
}
