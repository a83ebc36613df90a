//! [`BuildOptions`], the build's parameters (among them the [`Split`] rule), and the leaf
//! sizes it keeps to.

/// How a node's primitives are divided between its two children.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Split {
    /// The binned surface area heuristic: 16 bins on each axis, the cheapest plane.
    #[default]
    Sah,
    /// The longest axis of the centroids' box, at their median (half the primitives each
    /// side): the Delft template's scheme.
    Median,
}

/// Build parameters.
#[derive(Clone, Copy, Debug)]
pub struct BuildOptions {
    /// Leaf size: every subtree of at most this many primitives is one leaf (larger
    /// leaves are forced only when primitives cannot be separated); at most two for
    /// hierarchies over 64 primitives or fewer.
    pub max_leaf: usize,
    /// Cost of a traversal step relative to one primitive test, for the reported SAH cost.
    pub traversal_cost: f32,
    /// Subtrees with more primitives than this are built in parallel.
    pub parallel_threshold: usize,
    /// How nodes are split.
    pub split: Split,
}

impl Default for BuildOptions {
    fn default() -> BuildOptions {
        BuildOptions {
            // Four packs, the most a leaf reference holds. Split further, a subtree of
            // sixteen takes more slots or a node of the 8-wide tree to save at most two pack
            // tests, which with AVX are one test of eight lanes: on the 56k-triangle bunny,
            // leaves of sixteen rather than twelve make the tree about 30% smaller and the
            // build 7-12% faster, and trace as fast or faster.
            max_leaf: MAX_LEAF_REF,
            // One 8-wide node test replaces about three binary ones and costs about one
            // triangle pack test.
            traversal_cost: 0.5,
            parallel_threshold: 4096,
            split: Split::Sah,
        }
    }
}

/// Hierarchies over at most this many primitives keep leaves of at most two (on the
/// course's Cornell box, 17% fewer instructions per sample than full packs).
pub(crate) const SMALL_SCENE: usize = 64;

/// Largest leaf the build makes, even when primitives cannot be separated.
pub(crate) const MAX_LEAF_REF: usize = 16;
