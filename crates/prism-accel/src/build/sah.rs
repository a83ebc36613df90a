//! The binned surface-area-heuristic build of the binary tree: primitive references, 16
//! bins on each axis, the sweep, the partition, the large primitives set apart, parallel
//! halves above a size threshold; and the median split the Delft template asks for.

use prism_math::glam::Vec3A;
use prism_math::Aabb;
use rayon::prelude::*;

use super::node::{BuildNode, Summary};
use super::options::{BuildOptions, Split, MAX_LEAF_REF};
use crate::layout::root_list::FLAT_MAX;
use crate::layout::MEDIAN_DEPTH;
use crate::simd::bin_indices;

/// A primitive while building: its box and number. The build moves these, not indices, so
/// each pass over a node reads memory in order.
#[derive(Clone, Copy)]
pub(crate) struct PrimRef {
    pub(crate) bounds: Box3A,
    pub(crate) id: u32,
}

impl PrimRef {
    /// A placeholder for a primitive left out (no primitive has its number).
    pub(crate) const NONE: PrimRef = PrimRef {
        bounds: Box3A::EMPTY,
        id: u32::MAX,
    };

    /// Twice the box centre: the split position, without a multiply.
    #[inline(always)]
    pub(crate) fn centroid2(&self) -> Vec3A {
        self.bounds.min + self.bounds.max
    }
}

/// A box in SIMD registers, for the build's many unions.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Box3A {
    pub(crate) min: Vec3A,
    pub(crate) max: Vec3A,
}

impl Box3A {
    pub(crate) const EMPTY: Box3A = Box3A {
        min: Vec3A::splat(f32::INFINITY),
        max: Vec3A::splat(f32::NEG_INFINITY),
    };

    pub(crate) fn from_aabb(b: Aabb) -> Box3A {
        Box3A {
            min: b.min.into(),
            max: b.max.into(),
        }
    }

    pub(crate) fn to_aabb(self) -> Aabb {
        Aabb {
            min: self.min.into(),
            max: self.max.into(),
        }
    }

    #[inline(always)]
    pub(crate) fn union(self, o: Box3A) -> Box3A {
        Box3A {
            min: self.min.min(o.min),
            max: self.max.max(o.max),
        }
    }

    #[inline(always)]
    pub(crate) fn grow(self, p: Vec3A) -> Box3A {
        Box3A {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }

    #[inline(always)]
    pub(crate) fn area(self) -> f32 {
        let e = (self.max - self.min).max(Vec3A::ZERO);
        2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
    }
}

pub(crate) const BINS: usize = 16;

/// Primitives whose box has at least this fraction of the scene's surface area are large.
pub(crate) const BIG_AREA: f32 = 1.0 / 16.0;

/// At most this many large primitives are set apart.
pub(crate) const BIG_MAX: usize = 12;

/// Sets apart the large primitives of a scene with more than [`FLAT_MAX`] (walls and floors
/// of a room, among small ones): moves up to [`BIG_MAX`] of them (largest first) to the
/// front of `prims`, in primitive order, and returns how many (none if there are no small
/// ones to keep apart from). `b3` bounds the scene; over `parallel_threshold` primitives,
/// the search runs in parallel.
pub(crate) fn take_big(prims: &mut [PrimRef], b3: Box3A, parallel_threshold: usize) -> usize {
    if prims.len() <= FLAT_MAX {
        return 0;
    }
    let least = b3.area() * BIG_AREA;
    let big_one = |p: &PrimRef| {
        let area = p.bounds.area();
        (area >= least).then_some((area, p.id))
    };
    let mut big: Vec<(f32, u32)> = if prims.len() > parallel_threshold {
        prims.par_iter().filter_map(big_one).collect()
    } else {
        prims.iter().filter_map(big_one).collect()
    };
    if big.is_empty() || big.len() == prims.len() {
        return 0;
    }
    big.sort_unstable_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    big.truncate(BIG_MAX);
    let mut ids: Vec<u32> = big.iter().map(|b| b.1).collect();
    ids.sort_unstable();
    // A stable partition: the large ones first, each side in its old order.
    let (mut front, mut back): (Vec<PrimRef>, Vec<PrimRef>) = (Vec::new(), Vec::new());
    for p in prims.iter() {
        if ids.binary_search(&p.id).is_ok() {
            front.push(*p);
        } else {
            back.push(*p);
        }
    }
    let n = front.len();
    prims[..n].copy_from_slice(&front);
    prims[n..].copy_from_slice(&back);
    n
}

/// The union of the boxes of `prims` and the bounds of their doubled centroids (min and max
/// are exact, so the parallel reduction gives the same boxes as a sequential one).
pub(crate) fn bounds_of(prims: &[PrimRef], parallel_threshold: usize) -> (Box3A, Box3A) {
    let add = |(b, c): (Box3A, Box3A), p: &PrimRef| (b.union(p.bounds), c.grow(p.centroid2()));
    if prims.len() > parallel_threshold {
        prims
            .par_chunks(parallel_threshold)
            .map(|c| c.iter().fold((Box3A::EMPTY, Box3A::EMPTY), add))
            .reduce(
                || (Box3A::EMPTY, Box3A::EMPTY),
                |(a, b), (c, d)| (a.union(c), b.union(d)),
            )
    } else {
        prims.iter().fold((Box3A::EMPTY, Box3A::EMPTY), add)
    }
}

/// Per-axis bin counts and boxes of a set of primitives.
#[derive(Clone, Copy)]
pub(crate) struct Bins {
    pub(crate) counts: [[u32; BINS]; 3],
    pub(crate) boxes: [[Box3A; BINS]; 3],
}

impl Bins {
    pub(crate) const EMPTY: Bins = Bins {
        counts: [[0; BINS]; 3],
        boxes: [[Box3A::EMPTY; BINS]; 3],
    };

    #[inline(always)]
    pub(crate) fn add(&mut self, bin: [usize; 3], b: Box3A) {
        for (axis, &k) in bin.iter().enumerate() {
            let k = k % BINS;
            self.counts[axis][k] += 1;
            self.boxes[axis][k] = self.boxes[axis][k].union(b);
        }
    }

    /// The bins of both sets (counts add exactly and boxes unite exactly, so the order of
    /// merging does not matter).
    pub(crate) fn merge(mut self, o: &Bins) -> Bins {
        for axis in 0..3 {
            for k in 0..BINS {
                self.counts[axis][k] += o.counts[axis][k];
                self.boxes[axis][k] = self.boxes[axis][k].union(o.boxes[axis][k]);
            }
        }
        self
    }
}

/// Builds the subtree over `prims`, which start at `offset` in the final order; `b3` bounds
/// their boxes and `cb` their doubled centroids.
pub(crate) fn build_node(
    prims: &mut [PrimRef],
    offset: usize,
    depth: usize,
    opts: &BuildOptions,
    b3: Box3A,
    cb: Box3A,
) -> (BuildNode, Summary) {
    let bounds = b3.to_aabb();
    let n = prims.len();
    let leaf = || {
        (
            BuildNode::Leaf {
                bounds,
                start: offset,
                count: n,
            },
            Summary::leaf(&bounds, n, depth),
        )
    };
    // A subtree small enough for one leaf is one (see `BuildOptions::default`).
    if n <= opts.max_leaf {
        return leaf();
    }
    let extent = cb.max - cb.min;
    if opts.split == Split::Median {
        if extent.max_element() <= 0.0 && n <= MAX_LEAF_REF {
            // Every centroid coincides: nothing separates them.
            return leaf();
        }
        let mid = median_partition(prims, extent);
        let sides = sides_at(prims, mid);
        return children(prims, mid, sides, offset, depth, opts, bounds);
    }
    // Binned SAH on every axis with a non-degenerate centroid extent, all three axes binned
    // in one pass.
    let scale = Vec3A::select(
        extent.cmpgt(Vec3A::ZERO),
        Vec3A::splat(BINS as f32) / extent,
        Vec3A::ZERO,
    );
    let bin_of = |p: &PrimRef| bins((p.centroid2() - cb.min) * scale);
    let bin_all = |bins: &mut Bins, ps: &[PrimRef]| {
        for p in ps {
            bins.add(bin_of(p), p.bounds);
        }
    };
    let mut bins = Bins::EMPTY;
    if n > 4 * opts.parallel_threshold {
        bins = prims
            .par_chunks(opts.parallel_threshold)
            .map(|ps| {
                let mut b = Bins::EMPTY;
                bin_all(&mut b, ps);
                b
            })
            .reduce(|| Bins::EMPTY, |a, b| a.merge(&b));
    } else {
        bin_all(&mut bins, prims);
    }
    let Bins { counts, boxes } = &bins;
    let mut best: Option<(f32, usize, usize)> = None; // (cost, axis, split bin)
    for axis in 0..3 {
        if extent[axis] <= 0.0 {
            continue;
        }
        // Only non-empty bins matter: every split between two of them gives the same
        // sides, and the first such split is kept, as a sweep over all bins would.
        let mut full = [0usize; BINS];
        let mut m = 0;
        for (b, &count) in counts[axis].iter().enumerate() {
            if count > 0 {
                full[m] = b;
                m += 1;
            }
        }
        // Sweep from the right, then from the left.
        let mut right_area = [0f32; BINS];
        let mut right_count = [0u32; BINS];
        let (mut acc, mut c) = (Box3A::EMPTY, 0);
        for i in (1..m).rev() {
            acc = acc.union(boxes[axis][full[i]]);
            c += counts[axis][full[i]];
            right_area[i] = acc.area();
            right_count[i] = c;
        }
        let (mut acc, mut c) = (Box3A::EMPTY, 0);
        for i in 1..m {
            acc = acc.union(boxes[axis][full[i - 1]]);
            c += counts[axis][full[i - 1]];
            let cost = acc.area() * packs(c) + right_area[i] * packs(right_count[i]);
            if best.is_none_or(|(bc, _, _)| cost < bc) {
                best = Some((cost, axis, full[i - 1] + 1));
            }
        }
    }
    let split = match best {
        // Past this depth, median splits bound the remaining depth by log2(n).
        Some(_) if depth >= MEDIAN_DEPTH => None,
        Some((_, axis, split)) => Some((axis, split)),
        // Every centroid coincides: nothing separates them.
        None if n <= MAX_LEAF_REF => return leaf(),
        None => None,
    };
    // Partition, gathering each side's bounds on the way.
    let mut mid = 0;
    let mut sides = [(Box3A::EMPTY, Box3A::EMPTY); 2];
    if let Some((axis, split)) = split {
        // The four boxes stay in registers: one branch per primitive, no indexed stores.
        let [(mut lb, mut lc), (mut rb, mut rc)] = sides;
        for j in 0..n {
            let p = prims[j];
            if bin_of(&p)[axis] < split {
                lb = lb.union(p.bounds);
                lc = lc.grow(p.centroid2());
                prims.swap(mid, j);
                mid += 1;
            } else {
                rb = rb.union(p.bounds);
                rc = rc.grow(p.centroid2());
            }
        }
        sides = [(lb, lc), (rb, rc)];
    }
    if mid == 0 || mid == n {
        mid = n / 2;
        sides = sides_at(prims, mid);
    }
    children(prims, mid, sides, offset, depth, opts, bounds)
}

/// The node over `prims` (bounded by `bounds`) whose children are its first `mid` and its
/// other primitives, with those sides' boxes and doubled-centroid boxes.
fn children(
    prims: &mut [PrimRef],
    mid: usize,
    sides: [(Box3A, Box3A); 2],
    offset: usize,
    depth: usize,
    opts: &BuildOptions,
    bounds: Aabb,
) -> (BuildNode, Summary) {
    let n = prims.len();
    let (l, r) = prims.split_at_mut(mid);
    let [(lb, lc), (rb, rc)] = sides;
    let ((a, sa), (b, sb)) = if n > opts.parallel_threshold {
        rayon::join(
            || build_node(l, offset, depth + 1, opts, lb, lc),
            || build_node(r, offset + mid, depth + 1, opts, rb, rc),
        )
    } else {
        (
            build_node(l, offset, depth + 1, opts, lb, lc),
            build_node(r, offset + mid, depth + 1, opts, rb, rc),
        )
    };
    (
        BuildNode::interior(bounds, [a, b]),
        Summary::interior(&bounds, opts.traversal_cost, sa, sb),
    )
}

/// [`Split::Median`]'s partition of `prims` (more than a leaf holds): on the longest axis of
/// the centroids' box (`extent`, the first of equal ones), the half with the lower centroids
/// first (ties in primitive order); returns where the second half starts.
fn median_partition(prims: &mut [PrimRef], extent: Vec3A) -> usize {
    let axis = if extent.x >= extent.y && extent.x >= extent.z {
        0
    } else if extent.y >= extent.z {
        1
    } else {
        2
    };
    let mid = prims.len() / 2;
    prims.select_nth_unstable_by(mid, |a, b| {
        a.centroid2()[axis]
            .total_cmp(&b.centroid2()[axis])
            .then(a.id.cmp(&b.id))
    });
    mid
}

/// The boxes and doubled-centroid boxes of `prims[..mid]` and `prims[mid..]`.
fn sides_at(prims: &[PrimRef], mid: usize) -> [(Box3A, Box3A); 2] {
    let mut sides = [(Box3A::EMPTY, Box3A::EMPTY); 2];
    for (j, p) in prims.iter().enumerate() {
        let side = &mut sides[usize::from(j >= mid)];
        side.0 = side.0.union(p.bounds);
        side.1 = side.1.grow(p.centroid2());
    }
    sides
}

/// The bins (`0..BINS`) of scaled centroid offsets on the three axes: the integer parts,
/// with NaN taken as 0 and anything past the last bin put in it.
#[inline(always)]
pub(crate) fn bins(scaled: Vec3A) -> [usize; 3] {
    bin_indices(scaled.max(Vec3A::ZERO).min(Vec3A::splat((BINS - 1) as f32)))
}

/// Cost of testing `n` primitives: they are tested four at a time.
pub(crate) fn packs(n: u32) -> f32 {
    n.div_ceil(4) as f32
}
