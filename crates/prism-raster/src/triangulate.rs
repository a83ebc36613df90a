//! Polygon triangulation by ear clipping.

use prism_math::{DVec2, Vec2};

/// Ear-clipping triangulation as the course renderer performs it (in `f32`): the vertex
/// order is made counter-clockwise by the shoelace sign, the first candidate ear is
/// (last, first, second), and scanning resumes after a clipped ear. Returns triangles as
/// vertex triples; a polygon that cannot be fully clipped yields the triangles found so far.
#[must_use]
pub fn ear_clip(pts: &[DVec2]) -> Vec<[DVec2; 3]> {
    let n = pts.len();
    let mut out = Vec::new();
    if n < 3 {
        return out;
    }
    let f = |p: DVec2| Vec2::new(p.x as f32, p.y as f32);
    let mut area = 0f32;
    let mut p = n - 1;
    for q in 0..n {
        area = (f64::from(area) + (pts[p].x * pts[q].y - pts[q].x * pts[p].y)) as f32;
        p = q;
    }
    let area = area * 0.5;
    let mut v: Vec<usize> = if area > 0.0 {
        (0..n).collect()
    } else {
        (0..n).rev().collect()
    };
    let cross = |u: Vec2, w: Vec2| u.x * w.y - u.y * w.x;
    let inside = |a: Vec2, b: Vec2, c: Vec2, p: Vec2| {
        cross(c - b, p - b) >= 0.0 && cross(b - a, p - a) >= 0.0 && cross(a - c, p - c) >= 0.0
    };
    let mut nv = n;
    let mut count = 2 * nv;
    let mut vi = nv - 1;
    while nv > 2 {
        if count == 0 {
            break;
        }
        count -= 1;
        let mut u = vi;
        if u >= nv {
            u = 0;
        }
        vi = u + 1;
        if vi >= nv {
            vi = 0;
        }
        let mut w = vi + 1;
        if w >= nv {
            w = 0;
        }
        let (a, b, c) = (f(pts[v[u]]), f(pts[v[vi]]), f(pts[v[w]]));
        let convex = 1e-10f32 <= (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
        let ear = convex
            && (0..nv)
                .filter(|&k| k != u && k != vi && k != w)
                .all(|k| !inside(a, b, c, f(pts[v[k]])));
        if ear {
            out.push([pts[v[u]], pts[v[vi]], pts[v[w]]]);
            v.remove(vi);
            nv -= 1;
            count = 2 * nv;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Worked example from the course's triangulator: a counter-clockwise square.
    #[test]
    fn ear_clip_square_matches_course_order() {
        let sq = [
            DVec2::new(0.0, 0.0),
            DVec2::new(10.0, 0.0),
            DVec2::new(10.0, 10.0),
            DVec2::new(0.0, 10.0),
        ];
        let t = ear_clip(&sq);
        assert_eq!(t, vec![[sq[3], sq[0], sq[1]], [sq[1], sq[2], sq[3]]]);
    }

    /// Property: a simple polygon with n vertices gives n - 2 triangles whose areas sum to
    /// the polygon's area, concave or not, either orientation.
    #[test]
    fn ear_clip_preserves_area() {
        let star: Vec<DVec2> = (0..10)
            .map(|i| {
                let a = std::f64::consts::TAU * i as f64 / 10.0;
                let r = if i % 2 == 0 { 10.0 } else { 4.0 };
                DVec2::new(r * a.cos(), r * a.sin())
            })
            .collect();
        let area = |p: &[DVec2]| {
            (0..p.len())
                .map(|i| p[i].perp_dot(p[(i + 1) % p.len()]))
                .sum::<f64>()
                .abs()
                / 2.0
        };
        for poly in [star.clone(), star.iter().rev().copied().collect()] {
            let tris = ear_clip(&poly);
            assert_eq!(tris.len(), 8);
            let sum: f64 = tris.iter().map(|t| area(t)).sum();
            assert!((sum - area(&poly)).abs() < 1e-6 * area(&poly));
        }
    }
}
