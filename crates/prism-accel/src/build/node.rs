//! The binary tree the SAH build makes ([`BuildNode`]), with each subtree's least node
//! area in one to eight slots (for the collapse), and [`Summary`], the statistics gathered
//! on the way up.

use prism_math::Aabb;

pub(crate) enum BuildNode {
    Leaf {
        bounds: Aabb,
        start: usize,
        count: usize,
    },
    Interior {
        bounds: Aabb,
        children: Box<[BuildNode; 2]>,
        /// `slots[j - 1]`: the least total area of the 8-wide nodes of the subtree held in
        /// at most `j` slots of the node above it ([`BuildNode::interior`]), in `f64`, which
        /// no sum of areas of finite `f32` boxes overflows.
        slots: [f64; 8],
    },
}

impl BuildNode {
    /// An interior node over `children`, its slot costs computed from theirs.
    ///
    /// The 8-wide tree keeps the binary tree's leaves, so collapses differ only in their
    /// nodes, which a random ray visits with a chance proportional to their surface area:
    /// the collapse minimises the nodes' total area. A subtree given `j` slots of the node
    /// above it takes one, as a node of its own (its area, plus its children's cost in
    /// that node's eight slots), or, for `j` of two or more, hands `k` and `j - k` down to
    /// its two children: its cost in `j` slots is the least of these (a dynamic programme,
    /// as in Ylitie, Karras and Laine, "Efficient Incoherent Ray Traversal on GPUs Through
    /// Compressed Wide BVHs", 2017). A leaf's is zero.
    pub(crate) fn interior(bounds: Aabb, children: [BuildNode; 2]) -> BuildNode {
        let (a, b) = (children[0].slots(), children[1].slots());
        let mut slots = [0f64; 8];
        for (j, slot) in slots.iter_mut().enumerate().skip(1) {
            *slot = split_cost(&a, &b, j + 1).0;
        }
        slots[0] = area64(&bounds) + slots[7];
        for j in 1..8 {
            slots[j] = slots[j].min(slots[j - 1]);
        }
        BuildNode::Interior {
            bounds,
            children: Box::new(children),
            slots,
        }
    }

    /// The subtree's cost in at most `j` slots at `j - 1`.
    pub(crate) fn slots(&self) -> [f64; 8] {
        match self {
            BuildNode::Leaf { .. } => [0.0; 8],
            BuildNode::Interior { slots, .. } => *slots,
        }
    }
}

/// The surface area of `b`, in `f64`.
pub(crate) fn area64(b: &Aabb) -> f64 {
    let e = (b.max - b.min).as_dvec3();
    2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
}

/// The least cost of two subtrees with slot costs `a` and `b` sharing `j` >= 2 slots, and
/// the slots the first takes (the fewest of equals).
pub(crate) fn split_cost(a: &[f64; 8], b: &[f64; 8], j: usize) -> (f64, usize) {
    let mut best = (f64::INFINITY, 1);
    for k in 1..j {
        let c = a[k - 1] + b[j - k - 1];
        if c < best.0 {
            best = (c, k);
        }
    }
    best
}

/// What the build learns of a subtree on its way back up, so that no pass over the binary
/// tree is needed for the statistics.
#[derive(Clone, Copy, Default)]
pub(crate) struct Summary {
    pub(crate) leaves: usize,
    /// Deepest leaf, counted from the root of the whole tree.
    pub(crate) depth: usize,
    pub(crate) max_leaf: usize,
    /// Sum over the subtree's nodes of surface area times cost (in primitive tests).
    pub(crate) sah: f64,
}

impl Summary {
    pub(crate) fn leaf(bounds: &Aabb, count: usize, depth: usize) -> Summary {
        Summary {
            leaves: 1,
            depth,
            max_leaf: count,
            sah: f64::from(bounds.surface_area()) * count as f64,
        }
    }

    /// An interior node over subtrees `a` and `b`.
    pub(crate) fn interior(bounds: &Aabb, traversal_cost: f32, a: Summary, b: Summary) -> Summary {
        Summary {
            leaves: a.leaves + b.leaves,
            depth: a.depth.max(b.depth),
            max_leaf: a.max_leaf.max(b.max_leaf),
            sah: f64::from(bounds.surface_area() * traversal_cost) + (a.sah + b.sah),
        }
    }
}

pub(crate) fn root_bounds(n: &BuildNode) -> Aabb {
    match n {
        BuildNode::Leaf { bounds, .. } | BuildNode::Interior { bounds, .. } => *bounds,
    }
}

/// Frees a binary tree, the top levels' halves in parallel.
pub(crate) fn free(n: BuildNode, depth: usize) {
    if let BuildNode::Interior { children, .. } = n {
        let [a, b] = *children;
        if depth < 4 {
            rayon::join(|| free(a, depth + 1), || free(b, depth + 1));
        }
    }
}
