//! Figures: pictures of geometry built as [`Document`]s and rendered, such as mesh
//! wireframes and de Casteljau constructions of Bezier curves.
//!
//! Every figure is a square of `size` pixels, drawn at 16 samples per pixel over white.

use std::collections::HashSet;

use prism_image::Rgb8Image;
use prism_math::glam::DVec3;
use prism_math::{DVec2, Rgb};
use prism_mesh::{bezier_point, de_casteljau_levels, PolyMesh};

use crate::document::{Document, FillRule, Item, Mat3, Paint};
use crate::path::{LineCap, LineJoin, Path, StrokeStyle};
use crate::raster::{render, RasterError, RasterOptions};

/// Samples per pixel of every figure.
const FIGURE_SAMPLES: u32 = 16;

/// A document covering the unit square, y down, that a figure draws into.
fn unit_document() -> Document {
    Document {
        width: 1.0,
        height: 1.0,
        ..Document::default()
    }
}

/// Renders a unit-square document to a `size` x `size` picture over white.
fn picture(doc: &Document, size: u32) -> Result<Rgb8Image, RasterError> {
    let opts = RasterOptions {
        width: size,
        height: size,
        samples: FIGURE_SAMPLES,
        ..RasterOptions::default()
    };
    let (img, _) = render(doc, &opts)?;
    Ok(img.over_background([255, 255, 255]))
}

/// A round-joined, round-capped stroke in a solid colour.
fn stroke(path: Path, width: f64, color: Rgb) -> Item {
    Item::Stroke {
        path,
        transform: Mat3::IDENTITY,
        style: StrokeStyle {
            width,
            join: LineJoin::Round,
            cap: LineCap::Round,
            ..StrokeStyle::default()
        },
        paint: Paint::Solid(color),
        opacity: 1.0,
    }
}

/// A filled path in a solid colour.
fn fill(path: Path, color: Rgb) -> Item {
    Item::Fill {
        path,
        transform: Mat3::IDENTITY,
        rule: FillRule::NonZero,
        paint: Paint::Solid(color),
        opacity: 1.0,
    }
}

/// The wireframe's view: the mesh turned 0.6 radians about +y, then tilted 0.35 radians
/// about +x, projected orthographically and fitted into the unit square (y down) with a 5%
/// margin on its longer side.
fn wireframe_view(mesh: &PolyMesh) -> impl Fn(DVec3) -> DVec2 {
    let (sy, cy) = 0.6f64.sin_cos();
    let (sx, cx) = 0.35f64.sin_cos();
    let turn = move |p: DVec3| {
        let q = DVec3::new(cy * p.x + sy * p.z, p.y, -sy * p.x + cy * p.z);
        DVec2::new(q.x, cx * q.y - sx * q.z)
    };
    // Fit the turned mesh into the unit square with a margin.
    let (mut lo, mut hi) = (DVec2::splat(f64::MAX), DVec2::splat(f64::MIN));
    for &p in &mesh.positions {
        let q = turn(p);
        lo = lo.min(q);
        hi = hi.max(q);
    }
    let centre = (lo + hi) * 0.5;
    let scale = 0.9 / (hi - lo).max_element().max(1e-12);
    move |p: DVec3| {
        let q = (turn(p) - centre) * scale;
        DVec2::new(0.5 + q.x, 0.5 - q.y)
    }
}

/// A wireframe picture of a mesh, `size` x `size` pixels: every edge once, dark blue,
/// 1.2 pixels wide with round joins and caps, on white.
///
/// The mesh is turned 0.6 radians about +y, tilted 0.35 radians about +x, projected
/// orthographically onto the xy plane (+y up) and fitted into the picture with a 5% margin
/// on its longer side. An edge shared by several faces is drawn once.
///
/// # Errors
/// [`RasterError::BadSize`] if `size` is outside `1..=MAX_DIMENSION`.
pub fn wireframe(mesh: &PolyMesh, size: u32) -> Result<Rgb8Image, RasterError> {
    let view = wireframe_view(mesh);
    let mut path = Path::default();
    let mut seen = HashSet::new();
    for f in mesh.faces() {
        for k in 0..f.len() {
            let (a, b) = (f[k], f[(k + 1) % f.len()]);
            if seen.insert((a.min(b), a.max(b))) {
                path.move_to(view(mesh.positions[a as usize]));
                path.line_to(view(mesh.positions[b as usize]));
            }
        }
    }
    let mut doc = unit_document();
    doc.items.push(stroke(
        path,
        1.2 / f64::from(size),
        Rgb::new(0.1, 0.2, 0.45),
    ));
    picture(&doc, size)
}

/// A picture of a Bezier curve with its de Casteljau construction at `t`, `size` x `size`
/// pixels: the curve in near-black, then each level of the construction (the control
/// polygon first, the point on the curve last) as a polyline with a dot at each point,
/// coloured from blue to red by level.
///
/// Control points are in the unit square with y up (as `.bzc` files hold them); the
/// picture shows that square, y up.
///
/// # Errors
/// [`RasterError::BadSize`] if `size` is outside `1..=MAX_DIMENSION`.
///
/// # Panics
/// If `points` is empty.
pub fn de_casteljau_construction(
    points: &[DVec2],
    t: f64,
    size: u32,
) -> Result<Rgb8Image, RasterError> {
    // Curve files use [0, 1]^2 with y up; the picture has y down. The frame holds that
    // square and every control point, with a margin, so no point is cut off at the edge.
    let (mut lo, mut hi) = (DVec2::ZERO, DVec2::ONE);
    for &p in points.iter().filter(|p| p.is_finite()) {
        lo = lo.min(p);
        hi = hi.max(p);
    }
    let side = (hi - lo).max_element();
    let margin = 0.04 * side;
    let scale = side + 2.0 * margin;
    let centre = (lo + hi) / 2.0;
    let flip = move |p: DVec2| {
        let q = (p - centre) / scale;
        DVec2::new(0.5 + q.x, 0.5 - q.y)
    };
    let dot = |p: DVec2, r: f64, color: Rgb| fill(Path::ellipse(p, r, r), color);
    let mut doc = unit_document();
    doc.items.push(fill(
        Path::polygon(&[DVec2::ZERO, DVec2::X, DVec2::ONE, DVec2::Y], true),
        Rgb::WHITE,
    ));
    let curve: Vec<DVec2> = (0..=400)
        .map(|k| flip(bezier_point(points, k as f64 / 400.0)))
        .collect();
    doc.items.push(stroke(
        Path::polygon(&curve, false),
        0.006,
        Rgb::new(0.1, 0.1, 0.1),
    ));
    let levels = de_casteljau_levels(points, t);
    let n = levels.len().max(2) as f32;
    for (k, level) in levels.iter().enumerate() {
        let hue = k as f32 / (n - 1.0);
        let color = Rgb::new(0.15 + 0.8 * hue, 0.35, 0.9 - 0.7 * hue);
        let level: Vec<DVec2> = level.iter().map(|&p| flip(p)).collect();
        if level.len() > 1 {
            doc.items
                .push(stroke(Path::polygon(&level, false), 0.003, color));
        }
        for &p in &level {
            doc.items
                .push(dot(p, if level.len() == 1 { 0.012 } else { 0.008 }, color));
        }
    }
    picture(&doc, size)
}

#[cfg(test)]
mod tests {
    use super::*;

    const WHITE: [u8; 3] = [255, 255, 255];

    /// The pixel under a point of the unit square (y down) in a `size`-pixel picture.
    fn pixel(img: &Rgb8Image, p: DVec2) -> [u8; 3] {
        let size = f64::from(img.width());
        img.get((p.x * size) as u32, (p.y * size) as u32)
    }

    /// A dark pixel: clearly ink, not background or a faint edge of antialiasing.
    fn dark(c: [u8; 3]) -> bool {
        c.iter().map(|&v| u32::from(v)).sum::<u32>() < 3 * 160
    }

    /// Whether a pixel next to (or under) a point of the unit square is dark: a thin line
    /// through the point may cover only a corner of the pixel under it.
    fn ink_near(img: &Rgb8Image, p: DVec2) -> bool {
        let size = f64::from(img.width());
        let (x, y) = ((p.x * size) as i64, (p.y * size) as i64);
        (-1..=1).any(|dy| {
            (-1..=1).any(|dx| {
                let (u, v) = (x + dx, y + dy);
                (0..i64::from(img.width())).contains(&u)
                    && (0..i64::from(img.height())).contains(&v)
                    && dark(img.get(u as u32, v as u32))
            })
        })
    }

    #[test]
    fn wireframe_draws_a_triangles_edges_and_not_its_inside() {
        let mesh = PolyMesh::new(
            vec![DVec3::ZERO, DVec3::X, DVec3::new(0.3, 1.0, 0.2)],
            &[vec![0, 1, 2]],
        );
        let img = wireframe(&mesh, 100).unwrap();
        assert_eq!((img.width(), img.height()), (100, 100));
        let view = wireframe_view(&mesh);
        let corners: Vec<DVec2> = mesh.positions.iter().map(|&p| view(p)).collect();
        for k in 0..3 {
            let mid = (corners[k] + corners[(k + 1) % 3]) * 0.5;
            assert!(ink_near(&img, mid), "edge {k} at {mid}");
        }
        let centroid = (corners[0] + corners[1] + corners[2]) / 3.0;
        assert_eq!(pixel(&img, centroid), WHITE);
        assert_eq!(img.get(0, 0), WHITE);
        // The fit leaves a 5% margin on the longer side.
        let (lo, hi) = (
            corners.iter().fold(DVec2::MAX, |a, &b| a.min(b)),
            corners.iter().fold(DVec2::MIN, |a, &b| a.max(b)),
        );
        assert!(((hi - lo).max_element() - 0.9).abs() < 1e-12);
        assert!(((lo + hi) * 0.5 - DVec2::splat(0.5)).length() < 1e-12);
    }

    #[test]
    fn wireframe_refuses_a_zero_size() {
        let mesh = PolyMesh::new(vec![DVec3::ZERO, DVec3::X, DVec3::Y], &[vec![0, 1, 2]]);
        assert_eq!(wireframe(&mesh, 0), Err(RasterError::BadSize(0, 0)));
    }

    #[test]
    fn de_casteljau_construction_draws_the_curves_end_points_and_point_at_t() {
        let points = [
            DVec2::new(0.1, 0.1),
            DVec2::new(0.5, 0.9),
            DVec2::new(0.9, 0.1),
        ];
        let img = de_casteljau_construction(&points, 0.5, 200).unwrap();
        assert_eq!((img.width(), img.height()), (200, 200));
        // The frame is the unit square with a 4% margin each side.
        let flip = |p: DVec2| DVec2::new(0.5 + (p.x - 0.5) / 1.08, 0.5 - (p.y - 0.5) / 1.08);
        for p in [points[0], points[2], bezier_point(&points, 0.5)] {
            assert!(dark(pixel(&img, flip(p))), "{p}");
        }
        // Far from the curve and every level: background.
        assert_eq!(pixel(&img, flip(DVec2::new(0.5, 0.05))), WHITE);
        assert_eq!(pixel(&img, flip(DVec2::new(0.05, 0.95))), WHITE);
    }

    /// A control point on the edge of the unit square (the course's curve2.bzc ends at
    /// (1.0, 0.9)) is drawn whole: its dot has ink on both sides of its centre.
    #[test]
    fn control_points_on_the_edge_are_not_cut_off() {
        let points = [
            DVec2::new(0.2, 0.35),
            DVec2::new(0.3, 0.6),
            DVec2::new(0.5, 0.75),
            DVec2::new(0.7, 0.45),
            DVec2::new(1.0, 0.9),
        ];
        let img = de_casteljau_construction(&points, 0.5, 300).unwrap();
        let centre = DVec2::new(0.5 + 0.5 / 1.08, 0.5 - 0.4 / 1.08);
        for dx in [-0.004, 0.0, 0.004] {
            let p = centre + DVec2::new(dx, 0.0);
            assert_ne!(pixel(&img, p), WHITE, "{p}");
        }
        assert!(centre.x < 1.0 - 0.01);
    }
}
