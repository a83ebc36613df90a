//! Mitsuba's `roughplastic`: a diffuse base under a rough dielectric coat. The coat reflects
//! through microfacets; the base is seen through it, weighted by the coat's transmittance
//! toward both directions (a table over the cosine, as Mitsuba tabulates it) and by the
//! light the coat's inside sends back down.

use std::collections::HashMap;
use std::f32::consts::PI;
use std::sync::{Mutex, OnceLock};

use prism_math::warp::{cosine_hemisphere, cosine_hemisphere_pdf};
use prism_math::{Rgb, Vec2, Vec3};
use prism_scene::MicrofacetKind;

use super::microfacet::{self, Microfacet};
use super::{fresnel_dielectric, upper, BsdfSample};

/// Entries of the transmittance table, at cosines `0, 1/63, ..., 1` (Mitsuba's 64).
pub const TABLE_SIZE: usize = 64;

/// What a rough coat of one roughness and index lets through, computed once.
#[derive(Debug, PartialEq)]
pub struct CoatTables {
    /// The share of light arriving at cosine `i / 63` that the coat transmits (entry 0 at
    /// cosine 1e-6).
    pub transmittance: [f32; TABLE_SIZE],
    /// The share of light inside the coat, diffusely distributed, that the coat reflects
    /// back down (Mitsuba's estimate: twice the mean over the table's cosines of the
    /// cosine times the reflectance from inside).
    pub internal_reflectance: f32,
}

/// The coat tables of a distribution and index, shared: each distinct pair is computed
/// once per process (a few hundred bytes each).
pub fn coat_tables(distr: &Microfacet, eta: f32) -> &'static CoatTables {
    type Key = (bool, u32, u32);
    static CACHE: OnceLock<Mutex<HashMap<Key, &'static CoatTables>>> = OnceLock::new();
    let key = (
        distr.kind == MicrofacetKind::Ggx,
        distr.alpha_u.to_bits(),
        eta.to_bits(),
    );
    let cache = CACHE.get_or_init(|| Mutex::new(HashMap::new()));
    if let Some(t) = cache.lock().unwrap_or_else(|e| e.into_inner()).get(&key) {
        return t;
    }
    let tables: &'static CoatTables = Box::leak(Box::new(compute_tables(distr, eta)));
    let mut map = cache.lock().unwrap_or_else(|e| e.into_inner());
    let shared: &'static CoatTables = map.entry(key).or_insert(tables);
    shared
}

/// The tables by Gauss-Legendre quadrature over the visible normals' sample square.
fn compute_tables(distr: &Microfacet, eta: f32) -> CoatTables {
    let mut transmittance = [0.0f32; TABLE_SIZE];
    let mut internal = 0.0f64;
    for (i, t) in transmittance.iter_mut().enumerate() {
        let mu = (i as f32 / (TABLE_SIZE - 1) as f32).max(1e-6);
        let wi = Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
        *t = coat_integral(distr, wi, eta, false) as f32;
        internal += coat_integral(distr, wi, 1.0 / eta, true) * f64::from(mu);
    }
    CoatTables {
        transmittance,
        internal_reflectance: (internal / TABLE_SIZE as f64 * 2.0) as f32,
    }
}

/// The share of light from `wi` that a rough boundary of relative index `eta` reflects
/// (`reflect`) or transmits: the visible normals' mean of the Fresnel term times the
/// masking of the outgoing direction.
fn coat_integral(distr: &Microfacet, wi: Vec3, eta: f32, reflect: bool) -> f64 {
    let n = if eta > 1.0 { 64 } else { 128 };
    let (nodes, weights) = gauss_legendre(n);
    let mut total = 0.0f64;
    for (a, wa) in nodes.iter().zip(&weights) {
        for (b, wb) in nodes.iter().zip(&weights) {
            let u = Vec2::new((0.5 * a + 0.5) as f32, (0.5 * b + 0.5) as f32);
            let m = distr.sample_visible(wi, u);
            let c = wi.dot(m);
            let f = fresnel_dielectric(c, eta);
            let value = if reflect {
                let wo = microfacet::reflect(wi, m, c);
                if wo.z <= 0.0 {
                    0.0
                } else {
                    f * distr.g1(wo, m)
                }
            } else {
                match microfacet::refract(wi, m, c, eta) {
                    Some((wo, _)) if wo.z * wi.z < 0.0 => (1.0 - f) * distr.g1(wo, m),
                    _ => 0.0,
                }
            };
            total += f64::from(value) * wa * wb * 0.25;
        }
    }
    total
}

/// Gauss-Legendre nodes and weights of order `n` on [-1, 1] (Newton's method on the
/// Legendre polynomial from Chebyshev first guesses).
fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut nodes = Vec::with_capacity(n);
    let mut weights = Vec::with_capacity(n);
    for i in 0..n {
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
            let step = p1 / dp;
            x -= step;
            if step.abs() < 1e-15 {
                break;
            }
        }
        nodes.push(x);
        weights.push(2.0 / ((1.0 - x * x) * dp * dp));
    }
    (nodes, weights)
}

/// The table's value at cosine `x`, linear between entries (as Mitsuba reads it).
fn lookup(table: &[f32; TABLE_SIZE], x: f32) -> f32 {
    let x = x * (TABLE_SIZE - 1) as f32;
    let i = (x.max(0.0) as usize).min(TABLE_SIZE - 2);
    let t = x - i as f32;
    table[i] + (table[i + 1] - table[i]) * t
}

/// A rough plastic's parameters: the coat's distribution and index, the base's scaled
/// albedo, the coat's reflectance scale, the share of samples steered to the coat, and the
/// coat's tables.
pub(super) type PlasticParams = (Microfacet, f32, Rgb, Rgb, f32, &'static CoatTables);

/// The chance that a sample at `wo` picks the coat's lobe.
fn specular_share(cos_o: f32, weight: f32, tables: &CoatTables) -> f32 {
    let t = lookup(&tables.transmittance, cos_o);
    let s = (1.0 - t) * weight;
    let d = t * (1.0 - weight);
    s / (s + d)
}

/// A rough plastic's value (times `cos wi`) and sampling density.
pub(super) fn eval_pdf(
    (distr, eta, diffuse, specular, weight, tables): PlasticParams,
    wo: Vec3,
    wi: Vec3,
) -> (Rgb, f32) {
    if wo.z * wi.z <= 0.0 {
        return (Rgb::BLACK, 0.0);
    }
    let (wo, wi) = upper(wo, wi);
    let h = (wo + wi).normalize();
    let d = distr.d(h);
    let g1_o = distr.g1(wo, h);
    let f = fresnel_dielectric(wo.dot(h), eta);
    let coat = specular * (f * d * g1_o * distr.g1(wi, h) / (4.0 * wo.z));
    let t_o = lookup(&tables.transmittance, wo.z);
    let t_i = lookup(&tables.transmittance, wi.z);
    let base = diffuse * (wi.z / PI * t_o * t_i);
    let p = specular_share(wo.z, weight, tables);
    let pdf = p * d * g1_o / (4.0 * wo.z) + (1.0 - p) * cosine_hemisphere_pdf(wi.z);
    (coat + base, pdf)
}

/// Samples a rough plastic: the coat's visible normals with its share, else the cosine.
pub(super) fn sample(params: PlasticParams, wo: Vec3, u1: f32, u2: Vec2) -> Option<BsdfSample> {
    let (distr, _, _, _, weight, tables) = params;
    let side = if wo.z < 0.0 { -1.0 } else { 1.0 };
    let wo_up = Vec3::new(wo.x, wo.y, wo.z * side);
    if wo_up.z <= 0.0 {
        return None;
    }
    let wi = if u1 < specular_share(wo_up.z, weight, tables) {
        let m = distr.sample_visible(wo_up, u2);
        2.0 * wo_up.dot(m) * m - wo_up
    } else {
        cosine_hemisphere(u2)
    };
    if wi.z <= 0.0 {
        return None;
    }
    let wi = Vec3::new(wi.x, wi.y, wi.z * side);
    let (f, pdf) = eval_pdf(params, wo, wi);
    (pdf > 0.0).then(|| BsdfSample {
        wi,
        weight: f * (1.0 / pdf),
        pdf,
        delta: false,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Closed forms: Gauss-Legendre of order n integrates polynomials of degree 2n - 1
    /// exactly; a coat barely rough transmits 1 - F at each cosine (the smooth limit), and
    /// its inside reflects the known hemispherical average for a smooth boundary.
    #[test]
    fn quadrature_and_tables_meet_their_closed_forms() {
        let (x, w) = gauss_legendre(8);
        let integral: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(14)).sum();
        assert!((integral - 2.0 / 15.0).abs() < 1e-13, "{integral}");
        let smooth = Microfacet {
            kind: MicrofacetKind::Beckmann,
            alpha_u: 1e-4,
            alpha_v: 1e-4,
        };
        let tables = compute_tables(&smooth, 1.5);
        for i in [8, 32, 63] {
            let mu = i as f32 / 63.0;
            let want = 1.0 - fresnel_dielectric(mu, 1.5);
            assert!((tables.transmittance[i] - want).abs() < 2e-3, "{i}");
        }
        // Twice the mean of cos * F_inside over 64 cosines: close to the integral
        // 2 * int F(mu, 1/1.5) mu dmu = 0.596 (about 60% reflected inside).
        assert!(
            (tables.internal_reflectance - 0.596).abs() < 0.02,
            "{}",
            tables.internal_reflectance
        );
    }
}
