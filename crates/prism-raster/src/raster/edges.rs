//! Polygon edges in device space: how a polygon's outline is cut into edges, and how a
//! prepared polygon keeps them.

use prism_math::DVec2;

/// A non-horizontal polygon edge in device space with `y0 < y1`; `dir` is +1 where the
/// outline runs down (increasing y) and -1 where it runs up.
#[derive(Clone, Copy, Debug)]
pub(super) struct Edge {
    pub(super) x0: f64,
    pub(super) y0: f64,
    pub(super) y1: f64,
    pub(super) dxdy: f64,
    pub(super) dir: i32,
}

/// The non-horizontal edges of closed polygons (a prepared polygon keeps them as
/// [`Edges`], sized exactly).
pub(super) fn edges_of<'a>(polys: impl Iterator<Item = &'a [DVec2]>) -> Vec<Edge> {
    let mut out = Vec::new();
    for poly in polys {
        let n = poly.len();
        if n < 2 {
            continue;
        }
        for i in 0..n {
            let (a, b) = (poly[i], poly[(i + 1) % n]);
            if a.y == b.y || !a.is_finite() || !b.is_finite() {
                continue;
            }
            let (p, q, dir) = if a.y < b.y { (a, b, 1) } else { (b, a, -1) };
            out.push(Edge {
                x0: p.x,
                y0: p.y,
                y1: q.y,
                dxdy: (q.x - p.x) / (q.y - p.y),
                dir,
            });
        }
    }
    out
}

/// A prepared polygon's edges in the order given (sorted by `y0` for the band sweep):
/// `x0, y0, y1, dxdy` in 32 bytes an edge and the directions as bits, a fifth smaller than
/// a list of [`Edge`]s, which matters for strokes cut into many small pieces.
#[derive(Clone, Debug)]
pub(super) struct Edges {
    lines: Box<[[f64; 4]]>,
    /// Bit `i % 64` of word `i / 64` is set where edge `i` runs up (`dir` -1).
    up: Box<[u64]>,
}

impl Edges {
    /// Keeps `edges` in their order.
    pub(super) fn new(edges: &[Edge]) -> Edges {
        let mut up = vec![0u64; edges.len().div_ceil(64)];
        for (i, e) in edges.iter().enumerate() {
            if e.dir < 0 {
                up[i / 64] |= 1 << (i % 64);
            }
        }
        let lines = edges.iter().map(|e| [e.x0, e.y0, e.y1, e.dxdy]).collect();
        Edges {
            lines,
            up: up.into_boxed_slice(),
        }
    }

    /// Edge `i`.
    pub(super) fn get(&self, i: usize) -> Edge {
        let [x0, y0, y1, dxdy] = self.lines[i];
        let dir = if self.up[i / 64] >> (i % 64) & 1 == 1 {
            -1
        } else {
            1
        };
        Edge {
            x0,
            y0,
            y1,
            dxdy,
            dir,
        }
    }

    /// The number of leading edges whose top lies above `y` (the edges are sorted by top).
    pub(super) fn starting_above(&self, y: f64) -> usize {
        self.lines.partition_point(|l| l[1] < y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Brute force: every edge comes back from the compact store as it went in, with its
    /// direction, across several words of direction bits.
    #[test]
    fn edges_come_back_as_stored() {
        let edges: Vec<Edge> = (0..200)
            .map(|i| Edge {
                x0: f64::from(i) * 0.25,
                y0: f64::from(i),
                y1: f64::from(i) + 1.5,
                dxdy: -f64::from(i) / 7.0,
                dir: if (i * 7) % 3 == 0 { -1 } else { 1 },
            })
            .collect();
        let store = Edges::new(&edges);
        assert_eq!(store.starting_above(f64::INFINITY), edges.len());
        for (i, e) in edges.iter().enumerate() {
            let g = store.get(i);
            assert_eq!(
                (g.x0, g.y0, g.y1, g.dxdy, g.dir),
                (e.x0, e.y0, e.y1, e.dxdy, e.dir)
            );
        }
        assert_eq!(store.starting_above(10.0), 10);
        assert_eq!(store.starting_above(10.5), 11);
    }

    /// Closed form: a unit square gives its two vertical edges, one down and one up.
    #[test]
    fn a_square_has_two_edges() {
        let sq = [
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 0.0),
            DVec2::new(1.0, 1.0),
            DVec2::new(0.0, 1.0),
        ];
        let e = edges_of(std::iter::once(&sq[..]));
        assert_eq!(e.len(), 2);
        assert_eq!((e[0].x0, e[0].dir, e[1].x0, e[1].dir), (1.0, 1, 0.0, -1));
    }
}
