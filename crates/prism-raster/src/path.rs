//! Path geometry: segments, flattening to polylines, SVG arcs as cubics, stroking and
//! dashing. Everything here is pure geometry in `f64`; no pixels.

use prism_math::{DAffine2, DVec2};

/// One drawing command of a path. Quadratic curves and arcs are stored as the exactly
/// equivalent cubic (for quadratics) or the standard cubic approximation (for arcs, at most a
/// quarter turn per cubic, error below 3e-4 of the radius).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Segment {
    /// Starts a new subpath at the point.
    MoveTo(DVec2),
    /// A straight line to the point.
    LineTo(DVec2),
    /// A cubic Bezier with two control points and an end point.
    CubicTo(DVec2, DVec2, DVec2),
    /// Closes the current subpath with a line back to its start.
    Close,
}

/// A sequence of subpaths.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Path {
    /// The commands in order; every subpath begins with [`Segment::MoveTo`].
    pub segments: Vec<Segment>,
}

/// A flattened subpath: points joined by straight lines, closed or open.
#[derive(Clone, Debug, PartialEq)]
pub struct Polyline {
    /// The vertices in order.
    pub points: Vec<DVec2>,
    /// True if the last point connects back to the first.
    pub closed: bool,
}

/// How stroke segments meet at interior vertices.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LineJoin {
    /// Extend the outer edges to a point, falling back to bevel past the miter limit.
    #[default]
    Miter,
    /// A circular arc around the vertex.
    Round,
    /// A straight cut between the outer corners.
    Bevel,
}

/// How open stroke ends are finished.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LineCap {
    /// The stroke stops at the end point.
    #[default]
    Butt,
    /// A half disc around the end point.
    Round,
    /// A half square beyond the end point.
    Square,
}

/// Stroke geometry parameters, in the path's own (local) units.
#[derive(Clone, Debug, PartialEq)]
pub struct StrokeStyle {
    /// Full stroke width.
    pub width: f64,
    /// Join style.
    pub join: LineJoin,
    /// Cap style.
    pub cap: LineCap,
    /// Miter limit: the largest ratio of miter length to stroke width.
    pub miter_limit: f64,
    /// Dash lengths, alternating on and off; empty for a solid stroke.
    pub dashes: Vec<f64>,
    /// Distance into the dash pattern at which the stroke starts.
    pub dash_offset: f64,
}

impl Default for StrokeStyle {
    fn default() -> Self {
        StrokeStyle {
            width: 1.0,
            join: LineJoin::Miter,
            cap: LineCap::Butt,
            miter_limit: 4.0,
            dashes: Vec::new(),
            dash_offset: 0.0,
        }
    }
}

impl Path {
    /// Starts a subpath.
    pub fn move_to(&mut self, p: DVec2) {
        self.segments.push(Segment::MoveTo(p));
    }

    /// Adds a line.
    pub fn line_to(&mut self, p: DVec2) {
        self.segments.push(Segment::LineTo(p));
    }

    /// Adds a cubic Bezier.
    pub fn cubic_to(&mut self, c1: DVec2, c2: DVec2, p: DVec2) {
        self.segments.push(Segment::CubicTo(c1, c2, p));
    }

    /// Adds a quadratic Bezier from `from` as its exact cubic equivalent.
    pub fn quad_to(&mut self, from: DVec2, c: DVec2, p: DVec2) {
        self.cubic_to(
            from + (c - from) * (2.0 / 3.0),
            p + (c - p) * (2.0 / 3.0),
            p,
        );
    }

    /// Closes the current subpath.
    pub fn close(&mut self) {
        self.segments.push(Segment::Close);
    }

    /// A closed polygon through `points`.
    #[must_use]
    pub fn polygon(points: &[DVec2], closed: bool) -> Path {
        let mut p = Path::default();
        for (i, &q) in points.iter().enumerate() {
            if i == 0 {
                p.move_to(q);
            } else {
                p.line_to(q);
            }
        }
        if closed && !points.is_empty() {
            p.close();
        }
        p
    }

    /// An ellipse centred at `c` with radii `rx`, `ry`, as four cubics.
    #[must_use]
    pub fn ellipse(c: DVec2, rx: f64, ry: f64) -> Path {
        let k = 0.552_284_749_830_793_4; // 4/3 * tan(pi/8)
        let mut p = Path::default();
        let pt = |x: f64, y: f64| c + DVec2::new(x * rx, y * ry);
        p.move_to(pt(1.0, 0.0));
        p.cubic_to(pt(1.0, k), pt(k, 1.0), pt(0.0, 1.0));
        p.cubic_to(pt(-k, 1.0), pt(-1.0, k), pt(-1.0, 0.0));
        p.cubic_to(pt(-1.0, -k), pt(-k, -1.0), pt(0.0, -1.0));
        p.cubic_to(pt(k, -1.0), pt(1.0, -k), pt(1.0, 0.0));
        p.close();
        p
    }

    /// Appends an SVG elliptical arc from `from` to `to` (SVG 1.1 appendix F.6), as cubics.
    /// Zero radii give a straight line; too-small radii are scaled up as the spec requires.
    #[allow(clippy::too_many_arguments)]
    pub fn arc_to(
        &mut self,
        from: DVec2,
        rx: f64,
        ry: f64,
        x_rotation_deg: f64,
        large_arc: bool,
        sweep: bool,
        to: DVec2,
    ) {
        if from == to {
            return;
        }
        let (mut rx, mut ry) = (rx.abs(), ry.abs());
        if rx == 0.0 || ry == 0.0 {
            self.line_to(to);
            return;
        }
        let phi = x_rotation_deg.to_radians();
        let (sin_phi, cos_phi) = phi.sin_cos();
        // Step 1: compute (x1', y1')
        let d = (from - to) * 0.5;
        let x1p = cos_phi * d.x + sin_phi * d.y;
        let y1p = -sin_phi * d.x + cos_phi * d.y;
        // Ensure radii are large enough
        let lambda = (x1p * x1p) / (rx * rx) + (y1p * y1p) / (ry * ry);
        if lambda > 1.0 {
            let s = lambda.sqrt();
            rx *= s;
            ry *= s;
        }
        // Step 2: compute (cx', cy')
        let num = rx * rx * ry * ry - rx * rx * y1p * y1p - ry * ry * x1p * x1p;
        let den = rx * rx * y1p * y1p + ry * ry * x1p * x1p;
        let mut coef = if den == 0.0 {
            0.0
        } else {
            (num / den).max(0.0).sqrt()
        };
        if large_arc == sweep {
            coef = -coef;
        }
        let cxp = coef * rx * y1p / ry;
        let cyp = -coef * ry * x1p / rx;
        // Step 3: centre and angles
        let mid = (from + to) * 0.5;
        let c = DVec2::new(
            cos_phi * cxp - sin_phi * cyp + mid.x,
            sin_phi * cxp + cos_phi * cyp + mid.y,
        );
        let angle = |u: DVec2, v: DVec2| {
            let a = u.angle_to(v);
            if a.is_nan() {
                0.0
            } else {
                a
            }
        };
        let u = DVec2::new((x1p - cxp) / rx, (y1p - cyp) / ry);
        let v = DVec2::new((-x1p - cxp) / rx, (-y1p - cyp) / ry);
        let theta1 = angle(DVec2::X, u);
        let mut dtheta = angle(u, v);
        if !sweep && dtheta > 0.0 {
            dtheta -= std::f64::consts::TAU;
        } else if sweep && dtheta < 0.0 {
            dtheta += std::f64::consts::TAU;
        }
        // Split into pieces of at most a quarter turn
        let n = (dtheta.abs() / std::f64::consts::FRAC_PI_2).ceil().max(1.0) as usize;
        let step = dtheta / n as f64;
        let k = 4.0 / 3.0 * (step / 4.0).tan();
        let point = |t: f64| {
            let (s, co) = t.sin_cos();
            let e = DVec2::new(rx * co, ry * s);
            c + DVec2::new(cos_phi * e.x - sin_phi * e.y, sin_phi * e.x + cos_phi * e.y)
        };
        let deriv = |t: f64| {
            let (s, co) = t.sin_cos();
            let e = DVec2::new(-rx * s, ry * co);
            DVec2::new(cos_phi * e.x - sin_phi * e.y, sin_phi * e.x + cos_phi * e.y)
        };
        for i in 0..n {
            let t0 = theta1 + step * i as f64;
            let t1 = t0 + step;
            let p0 = point(t0);
            let p1 = if i + 1 == n { to } else { point(t1) };
            self.cubic_to(p0 + deriv(t0) * k, p1 - deriv(t1) * k, p1);
        }
    }

    /// Applies an affine transform to every point.
    #[must_use]
    pub fn transformed(&self, m: &DAffine2) -> Path {
        let t = |p: DVec2| m.transform_point2(p);
        Path {
            segments: self
                .segments
                .iter()
                .map(|s| match *s {
                    Segment::MoveTo(p) => Segment::MoveTo(t(p)),
                    Segment::LineTo(p) => Segment::LineTo(t(p)),
                    Segment::CubicTo(a, b, p) => Segment::CubicTo(t(a), t(b), t(p)),
                    Segment::Close => Segment::Close,
                })
                .collect(),
        }
    }

    /// True if every coordinate is finite.
    #[must_use]
    pub fn is_finite(&self) -> bool {
        self.segments.iter().all(|s| match *s {
            Segment::MoveTo(p) | Segment::LineTo(p) => p.is_finite(),
            Segment::CubicTo(a, b, p) => a.is_finite() && b.is_finite() && p.is_finite(),
            Segment::Close => true,
        })
    }

    /// Flattens to polylines so that no point of a curve is farther than `tolerance` from
    /// the polyline (uniform subdivision with the second-difference bound).
    #[must_use]
    pub fn flatten(&self, tolerance: f64) -> Vec<Polyline> {
        self.flatten_within(tolerance, None)
    }

    /// [`Path::flatten`], except that a curve whose control points all lie outside `keep`
    /// (a box `(min, max)`) becomes its chord: what lies outside the box is not drawn, and
    /// the region between a curve and its chord lies in the curve's control hull, so no
    /// point of the box changes sides. The work then follows what can be seen, not the
    /// curve's size.
    #[must_use]
    pub fn flatten_within(&self, tolerance: f64, keep: Option<(DVec2, DVec2)>) -> Vec<Polyline> {
        let mut out = Vec::new();
        let mut cur: Vec<DVec2> = Vec::new();
        let flush = |cur: &mut Vec<DVec2>, out: &mut Vec<Polyline>, closed: bool| {
            if !cur.is_empty() {
                out.push(Polyline {
                    points: std::mem::take(cur),
                    closed,
                });
            }
        };
        let mut start = DVec2::ZERO;
        for s in &self.segments {
            match *s {
                Segment::MoveTo(p) => {
                    flush(&mut cur, &mut out, false);
                    cur.push(p);
                    start = p;
                }
                Segment::LineTo(p) => {
                    if cur.is_empty() {
                        cur.push(start);
                    }
                    cur.push(p);
                }
                Segment::CubicTo(c1, c2, p) => {
                    if cur.is_empty() {
                        cur.push(start);
                    }
                    let p0 = *cur.last().expect("non-empty");
                    let outside = keep.is_some_and(|(lo, hi)| {
                        let a = p0.min(c1).min(c2.min(p));
                        let b = p0.max(c1).max(c2.max(p));
                        a.x > hi.x || a.y > hi.y || b.x < lo.x || b.y < lo.y
                    });
                    if outside {
                        cur.push(p);
                    } else {
                        flatten_cubic(p0, c1, c2, p, tolerance, &mut cur);
                    }
                }
                Segment::Close => {
                    flush(&mut cur, &mut out, true);
                }
            }
        }
        flush(&mut cur, &mut out, false);
        out
    }
}

fn flatten_cubic(p0: DVec2, p1: DVec2, p2: DVec2, p3: DVec2, tol: f64, out: &mut Vec<DVec2>) {
    let dd = (p0 - 2.0 * p1 + p2)
        .length()
        .max((p1 - 2.0 * p2 + p3).length());
    let n = (0.75 * dd / tol.max(1e-9)).sqrt().ceil();
    let n = if n.is_finite() {
        n.clamp(1.0, 4096.0) as usize
    } else {
        1
    };
    for i in 1..=n {
        let t = i as f64 / n as f64;
        let u = 1.0 - t;
        let p =
            p0 * (u * u * u) + p1 * (3.0 * u * u * t) + p2 * (3.0 * u * t * t) + p3 * (t * t * t);
        out.push(if i == n { p3 } else { p });
    }
}

/// A closed polygon approximating a circle of radius `r` within `tol`.
fn circle(c: DVec2, r: f64, tol: f64) -> Vec<DVec2> {
    let n = if r <= tol {
        8
    } else {
        let n = std::f64::consts::PI / (1.0 - tol / r).clamp(-1.0, 1.0).acos();
        (n.ceil() as usize).clamp(8, 1024)
    };
    (0..n)
        .map(|i| {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            c + DVec2::new(a.cos(), a.sin()) * r
        })
        .collect()
}

fn signed_area(poly: &[DVec2]) -> f64 {
    let mut a = 0.0;
    for i in 0..poly.len() {
        let p = poly[i];
        let q = poly[(i + 1) % poly.len()];
        a += p.x * q.y - q.x * p.y;
    }
    a * 0.5
}

fn push_oriented(out: &mut Vec<Vec<DVec2>>, mut poly: Vec<DVec2>) {
    let a = signed_area(&poly);
    if a == 0.0 || !a.is_finite() {
        return;
    }
    if a < 0.0 {
        poly.reverse();
    }
    out.push(poly);
}

/// Splits polylines into dashes. `dashes` must hold positive total length.
fn dash(lines: &[Polyline], dashes: &[f64], offset: f64) -> Vec<Polyline> {
    let total: f64 = dashes.iter().sum();
    let mut out = Vec::new();
    for line in lines {
        let mut pts = line.points.clone();
        if line.closed && pts.len() > 1 {
            pts.push(pts[0]);
        }
        // Position in the pattern.
        let mut idx = 0;
        let mut left = offset.rem_euclid(total);
        while left >= dashes[idx] {
            left -= dashes[idx];
            idx = (idx + 1) % dashes.len();
        }
        let mut remaining = dashes[idx] - left;
        let mut on = idx % 2 == 0;
        let mut cur: Vec<DVec2> = if on { vec![pts[0]] } else { Vec::new() };
        for w in pts.windows(2) {
            let (a, b) = (w[0], w[1]);
            let len = (b - a).length();
            let mut pos = 0.0;
            while len - pos > remaining {
                pos += remaining;
                let p = a + (b - a) * (pos / len);
                if on {
                    cur.push(p);
                    out.push(Polyline {
                        points: std::mem::take(&mut cur),
                        closed: false,
                    });
                } else {
                    cur = vec![p];
                }
                on = !on;
                idx = (idx + 1) % dashes.len();
                remaining = dashes[idx];
            }
            remaining -= len - pos;
            if on {
                cur.push(b);
            }
        }
        if on && cur.len() > 1 {
            out.push(Polyline {
                points: cur,
                closed: false,
            });
        }
    }
    out
}

/// Most dashes one stroke may be cut into; a longer dashed stroke is drawn solid.
pub const MAX_DASHES: f64 = 1e6;

/// Outlines the stroke of `lines` as closed counter-clockwise polygons whose union (filled
/// with the non-zero rule) is the stroked area. `tol` bounds the error of round joins and
/// caps, in the same units as the geometry. A dash pattern that would cut the stroke into
/// more than [`MAX_DASHES`] pieces is ignored (the stroke is drawn solid).
#[must_use]
pub fn stroke(lines: &[Polyline], style: &StrokeStyle, tol: f64) -> Vec<Vec<DVec2>> {
    let hw = style.width * 0.5;
    let mut out = Vec::new();
    if hw <= 0.0 || !hw.is_finite() {
        return out;
    }
    let dashed;
    let pattern: f64 = style.dashes.iter().sum();
    let length: f64 = lines
        .iter()
        .map(|l| {
            let mut len: f64 = l.points.windows(2).map(|w| (w[1] - w[0]).length()).sum();
            if l.closed && l.points.len() > 1 {
                len += (l.points[0] - l.points[l.points.len() - 1]).length();
            }
            len
        })
        .sum();
    let dash_count = length / pattern * style.dashes.len() as f64;
    let lines = if !style.dashes.is_empty()
        && style.dashes.iter().all(|d| *d >= 0.0 && d.is_finite())
        && pattern > 0.0
        && dash_count <= MAX_DASHES
    {
        dashed = dash(lines, &style.dashes, style.dash_offset);
        &dashed[..]
    } else {
        lines
    };
    for line in lines {
        let mut pts: Vec<DVec2> = Vec::with_capacity(line.points.len());
        for &p in &line.points {
            if pts.last() != Some(&p) {
                pts.push(p);
            }
        }
        if line.closed && pts.len() > 2 && pts.first() == pts.last() {
            pts.pop();
        }
        if pts.len() == 1 {
            // A zero-length subpath shows only its caps.
            let c = pts[0];
            match style.cap {
                LineCap::Round => push_oriented(&mut out, circle(c, hw, tol)),
                LineCap::Square => push_oriented(
                    &mut out,
                    vec![
                        c + DVec2::new(-hw, -hw),
                        c + DVec2::new(hw, -hw),
                        c + DVec2::new(hw, hw),
                        c + DVec2::new(-hw, hw),
                    ],
                ),
                LineCap::Butt => {}
            }
            continue;
        }
        let closed = line.closed && pts.len() > 2;
        let n = pts.len();
        let seg_count = if closed { n } else { n - 1 };
        for i in 0..seg_count {
            let a = pts[i];
            let b = pts[(i + 1) % n];
            let d = (b - a).normalize();
            let nrm = d.perp() * hw;
            push_oriented(&mut out, vec![a + nrm, b + nrm, b - nrm, a - nrm]);
        }
        // Joins
        let join_at = |i: usize, out: &mut Vec<Vec<DVec2>>| {
            let p = pts[i];
            let prev = pts[(i + n - 1) % n];
            let next = pts[(i + 1) % n];
            let d0 = (p - prev).normalize();
            let d1 = (next - p).normalize();
            let cross = d0.perp_dot(d1);
            if cross.abs() < 1e-12 && d0.dot(d1) > 0.0 {
                return;
            }
            match style.join {
                LineJoin::Round => push_oriented(out, circle(p, hw, tol)),
                LineJoin::Bevel | LineJoin::Miter => {
                    let s = if cross > 0.0 { -1.0 } else { 1.0 };
                    let a = p + d0.perp() * (hw * s);
                    let b = p + d1.perp() * (hw * s);
                    let mut poly = vec![p, a, b];
                    if style.join == LineJoin::Miter {
                        let m = (d0.perp() + d1.perp()) * s;
                        let ml = m.length();
                        if ml > 1e-12 {
                            let m = m / ml;
                            let cos_half = m.dot(d0.perp() * s);
                            // miter length / stroke width = 1 / sin(theta/2) = 1 / cos_half
                            if cos_half > 1e-12 && 1.0 / cos_half <= style.miter_limit {
                                poly = vec![p, a, p + m * (hw / cos_half), b];
                            }
                        }
                    }
                    push_oriented(out, poly);
                }
            }
        };
        let (first, last) = if closed { (0, n) } else { (1, n - 1) };
        for i in first..last {
            join_at(i, &mut out);
        }
        if !closed {
            for (end, dir) in [
                (pts[0], (pts[0] - pts[1]).normalize()),
                (pts[n - 1], (pts[n - 1] - pts[n - 2]).normalize()),
            ] {
                match style.cap {
                    LineCap::Butt => {}
                    LineCap::Round => push_oriented(&mut out, circle(end, hw, tol)),
                    LineCap::Square => {
                        let nrm = dir.perp() * hw;
                        let ext = dir * hw;
                        push_oriented(
                            &mut out,
                            vec![end + nrm, end + nrm + ext, end - nrm + ext, end - nrm],
                        );
                    }
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area_of_union_estimate(polys: &[Vec<DVec2>], lo: DVec2, hi: DVec2, n: usize) -> f64 {
        // Brute-force: count grid points covered by any polygon (non-zero winding).
        let mut hits = 0usize;
        for j in 0..n {
            for i in 0..n {
                let p = lo
                    + (hi - lo)
                        * DVec2::new((i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64);
                let mut wind = 0i32;
                for poly in polys {
                    for k in 0..poly.len() {
                        let a = poly[k];
                        let b = poly[(k + 1) % poly.len()];
                        if (a.y <= p.y) != (b.y <= p.y) {
                            let x = a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x);
                            if x > p.x {
                                wind += if b.y > a.y { 1 } else { -1 };
                            }
                        }
                    }
                }
                hits += usize::from(wind != 0);
            }
        }
        let cell = (hi - lo).x * (hi - lo).y / (n * n) as f64;
        hits as f64 * cell
    }

    /// Closed form: a butt-capped straight stroke covers length x width.
    #[test]
    fn straight_stroke_area() {
        let line = Polyline {
            points: vec![DVec2::new(0.0, 0.0), DVec2::new(10.0, 0.0)],
            closed: false,
        };
        let polys = stroke(
            std::slice::from_ref(&line),
            &StrokeStyle {
                width: 2.0,
                ..Default::default()
            },
            0.01,
        );
        let a = area_of_union_estimate(&polys, DVec2::new(-3.0, -3.0), DVec2::new(13.0, 3.0), 400);
        assert!((a - 20.0).abs() < 0.3, "area {a}");
        let polys = stroke(
            &[line],
            &StrokeStyle {
                width: 2.0,
                cap: LineCap::Round,
                ..Default::default()
            },
            0.001,
        );
        let a = area_of_union_estimate(&polys, DVec2::new(-3.0, -3.0), DVec2::new(13.0, 3.0), 400);
        assert!((a - (20.0 + std::f64::consts::PI)).abs() < 0.3, "area {a}");
    }

    /// Closed form: a closed square outline with miter joins is the difference of squares.
    #[test]
    fn closed_square_miter_area() {
        let sq = Polyline {
            points: vec![
                DVec2::new(0.0, 0.0),
                DVec2::new(10.0, 0.0),
                DVec2::new(10.0, 10.0),
                DVec2::new(0.0, 10.0),
            ],
            closed: true,
        };
        let polys = stroke(
            &[sq],
            &StrokeStyle {
                width: 2.0,
                ..Default::default()
            },
            0.01,
        );
        let a = area_of_union_estimate(&polys, DVec2::new(-2.0, -2.0), DVec2::new(12.0, 12.0), 560);
        assert!((a - (144.0 - 64.0)).abs() < 0.3, "area {a}");
    }

    /// Property: arcs end exactly at their end point and stay on the circle.
    #[test]
    fn arc_lies_on_circle() {
        let mut p = Path::default();
        let from = DVec2::new(10.0, 0.0);
        p.move_to(from);
        p.arc_to(from, 10.0, 10.0, 0.0, true, true, DVec2::new(0.0, -10.0));
        let lines = p.flatten(1e-4);
        let pts = &lines[0].points;
        assert_eq!(*pts.last().unwrap(), DVec2::new(0.0, -10.0));
        for q in pts {
            assert!((q.length() - 10.0).abs() < 5e-3, "{q}");
        }
        // Large sweep arc covers three quarters: passes through (0, 10) and (-10, 0).
        assert!(pts
            .iter()
            .any(|q| (*q - DVec2::new(-10.0, 0.0)).length() < 0.05));
    }

    /// Closed form: flattening error of a cubic stays within tolerance of the true curve.
    #[test]
    fn flatten_error_bound() {
        let (p0, p1, p2, p3) = (
            DVec2::ZERO,
            DVec2::new(0.0, 100.0),
            DVec2::new(100.0, 100.0),
            DVec2::new(100.0, 0.0),
        );
        let mut out = vec![p0];
        flatten_cubic(p0, p1, p2, p3, 0.1, &mut out);
        for k in 0..1000 {
            let t = k as f64 / 999.0;
            let u = 1.0 - t;
            let b = p0 * (u * u * u)
                + p1 * (3.0 * u * u * t)
                + p2 * (3.0 * u * t * t)
                + p3 * (t * t * t);
            let d = out
                .windows(2)
                .map(|w| {
                    let (a, c) = (w[0], w[1]);
                    let t = ((b - a).dot(c - a) / (c - a).length_squared()).clamp(0.0, 1.0);
                    (a + (c - a) * t - b).length()
                })
                .fold(f64::INFINITY, f64::min);
            assert!(d <= 0.1 + 1e-9, "deviation {d}");
        }
    }

    /// Regression (found by fuzzing): an astronomically long dashed stroke stays bounded.
    #[test]
    fn absurd_dash_counts_fall_back_to_solid() {
        let line = Polyline {
            points: vec![DVec2::new(0.0, 0.0), DVec2::new(1e78, 0.0)],
            closed: false,
        };
        let style = StrokeStyle {
            dashes: vec![20.0, 10.0],
            ..Default::default()
        };
        assert_eq!(stroke(&[line], &style, 0.1).len(), 1);
    }

    #[test]
    fn dashes_split_by_length() {
        let line = Polyline {
            points: vec![DVec2::new(0.0, 0.0), DVec2::new(10.0, 0.0)],
            closed: false,
        };
        let d = dash(&[line], &[3.0, 1.0], 0.0);
        let xs: Vec<(f64, f64)> = d
            .iter()
            .map(|l| (l.points[0].x, l.points.last().unwrap().x))
            .collect();
        assert_eq!(xs, vec![(0.0, 3.0), (4.0, 7.0), (8.0, 10.0)]);
    }
}
