//! `feDiffuseLighting` and `feSpecularLighting`: the alpha channel as a height field lit by
//! a distant, point or spot light (Sobel normals; light positions in canvas pixels).

use prism_math::glam::DVec3;
use prism_math::{DAffine2, DVec2};
use usvg::filter::{DiffuseLighting, LightSource, SpecularLighting};

use super::Img;

/// The light in canvas pixels: point and spot positions mapped by `ts`, heights scaled by
/// the transform's mean scale.
fn place(light: LightSource, ts: &DAffine2) -> LightSource {
    let sz = ((ts.matrix2.x_axis.x.powi(2) + ts.matrix2.y_axis.y.powi(2)) / 2.0).sqrt() as f32;
    let map = |x: f32, y: f32| {
        let p = ts.transform_point2(DVec2::new(f64::from(x), f64::from(y)));
        (p.x as f32, p.y as f32)
    };
    match light {
        LightSource::DistantLight(d) => LightSource::DistantLight(d),
        LightSource::PointLight(mut p) => {
            (p.x, p.y) = map(p.x, p.y);
            p.z *= sz;
            LightSource::PointLight(p)
        }
        LightSource::SpotLight(mut s) => {
            (s.x, s.y) = map(s.x, s.y);
            s.z *= sz;
            (s.points_at_x, s.points_at_y) = map(s.points_at_x, s.points_at_y);
            s.points_at_z *= sz;
            LightSource::SpotLight(s)
        }
    }
}

/// Lights `input`'s alpha surface; `shade(normal, light direction, light colour)` gives a
/// pixel's premultiplied result. The lighting colour is taken as given, in whichever colour
/// space the primitive works in (as resvg does).
fn light(
    input: &Img,
    surface_scale: f32,
    source: LightSource,
    color: usvg::Color,
    shade: impl Fn(DVec3, DVec3, [f64; 3]) -> [f32; 4],
) -> Img {
    let (w, h) = (input.w as i64, input.h as i64);
    let ss = f64::from(surface_scale);
    let alpha = |x: i64, y: i64| {
        f64::from(input.px[(y.clamp(0, h - 1) * w + x.clamp(0, w - 1)) as usize][3])
    };
    let base = [color.red, color.green, color.blue].map(|c| f64::from(c) / 255.0);
    let mut px = vec![[0.0f32; 4]; input.px.len()];
    for y in 0..h {
        for x in 0..w {
            let a = |dx: i64, dy: i64| alpha(x + dx, y + dy);
            let nx = -ss / 4.0
                * ((a(1, -1) + 2.0 * a(1, 0) + a(1, 1)) - (a(-1, -1) + 2.0 * a(-1, 0) + a(-1, 1)));
            let ny = -ss / 4.0
                * ((a(-1, 1) + 2.0 * a(0, 1) + a(1, 1)) - (a(-1, -1) + 2.0 * a(0, -1) + a(1, -1)));
            let n = DVec3::new(nx, ny, 1.0).normalize();
            let z = ss * a(0, 0);
            let surface = DVec3::new(x as f64, y as f64, z);
            let (l, c) = match source {
                LightSource::DistantLight(d) => {
                    let (az, el) = (
                        f64::from(d.azimuth).to_radians(),
                        f64::from(d.elevation).to_radians(),
                    );
                    (
                        DVec3::new(az.cos() * el.cos(), az.sin() * el.cos(), el.sin()),
                        base,
                    )
                }
                LightSource::PointLight(p) => {
                    let pos = DVec3::new(f64::from(p.x), f64::from(p.y), f64::from(p.z));
                    ((pos - surface).normalize_or_zero(), base)
                }
                LightSource::SpotLight(s) => {
                    let pos = DVec3::new(f64::from(s.x), f64::from(s.y), f64::from(s.z));
                    let at = DVec3::new(
                        f64::from(s.points_at_x),
                        f64::from(s.points_at_y),
                        f64::from(s.points_at_z),
                    );
                    let l = (pos - surface).normalize_or_zero();
                    let dir = (at - pos).normalize_or_zero();
                    let m = -l.dot(dir);
                    let inside = s
                        .limiting_cone_angle
                        .is_none_or(|ang| m >= f64::from(ang).to_radians().cos());
                    let k = if m > 0.0 && inside {
                        m.powf(f64::from(s.specular_exponent.get()))
                    } else {
                        0.0
                    };
                    (l, base.map(|v| v * k))
                }
            };
            px[(y * w + x) as usize] = shade(n, l, c);
        }
    }
    Img {
        px: std::sync::Arc::new(px),
        ..input.clone()
    }
}

/// `feDiffuseLighting`: `kd (N . L)` times the light colour, opaque.
pub(crate) fn diffuse(input: &Img, fe: &DiffuseLighting, ts: &DAffine2) -> Img {
    let kd = f64::from(fe.diffuse_constant());
    light(
        input,
        fe.surface_scale(),
        place(fe.light_source(), ts),
        fe.lighting_color(),
        |n, l, c| {
            let k = kd * n.dot(l).max(0.0);
            [
                (k * c[0]).clamp(0.0, 1.0) as f32,
                (k * c[1]).clamp(0.0, 1.0) as f32,
                (k * c[2]).clamp(0.0, 1.0) as f32,
                1.0,
            ]
        },
    )
}

/// `feSpecularLighting`: `ks (N . H)^exponent` times the light colour, alpha the largest
/// channel.
pub(crate) fn specular(input: &Img, fe: &SpecularLighting, ts: &DAffine2) -> Img {
    let ks = f64::from(fe.specular_constant());
    let e = f64::from(fe.specular_exponent());
    light(
        input,
        fe.surface_scale(),
        place(fe.light_source(), ts),
        fe.lighting_color(),
        |n, l, c| {
            let hv = (l + DVec3::Z).normalize_or_zero();
            let k = ks * n.dot(hv).max(0.0).powf(e);
            let rgb = c.map(|v| (k * v).clamp(0.0, 1.0) as f32);
            [rgb[0], rgb[1], rgb[2], rgb[0].max(rgb[1]).max(rgb[2])]
        },
    )
}
