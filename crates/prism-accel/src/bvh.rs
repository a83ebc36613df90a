use prism_math::glam::Vec3A;
use prism_math::{Aabb, Ray, Vec3};

use crate::shapes::{intersect_sphere, intersect_triangle, RayPre, Sphere};

/// Build parameters.
#[derive(Clone, Copy, Debug)]
pub struct BuildOptions {
    /// Largest leaf the heuristic may choose (a leaf is forced only when primitives cannot
    /// be separated).
    pub max_leaf: usize,
    /// Cost of a traversal step relative to one primitive test.
    pub traversal_cost: f32,
    /// Subtrees with more primitives than this are built in parallel.
    pub parallel_threshold: usize,
}

impl Default for BuildOptions {
    fn default() -> BuildOptions {
        BuildOptions {
            max_leaf: 8,
            traversal_cost: 2.0,
            parallel_threshold: 4096,
        }
    }
}

/// The closest (or any) hit along a ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Ray parameter of the hit.
    pub t: f32,
    /// The primitive: triangles are numbered first, then spheres.
    pub prim: u32,
    /// Barycentric weight of the triangle's second vertex (0 for spheres).
    pub b1: f32,
    /// Barycentric weight of the triangle's third vertex (0 for spheres).
    pub b2: f32,
}

/// Build statistics.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BvhStats {
    /// Triangles and spheres.
    pub primitives: usize,
    /// All nodes.
    pub nodes: usize,
    /// Leaf nodes.
    pub leaves: usize,
    /// Deepest leaf (the root has depth 0).
    pub depth: usize,
    /// Largest leaf.
    pub max_leaf_size: usize,
    /// The surface area heuristic's expected cost of a random ray (in primitive tests, with
    /// the build's traversal cost): the sum over nodes of their area relative to the root's
    /// times their cost.
    pub sah_cost: f32,
    /// Bytes held: nodes, reordered triangle vertices, spheres and primitive numbers.
    pub bytes: usize,
}

/// A flattened node: 32 bytes. Interior nodes keep their first child right after them and
/// the second at `index`; leaves hold `count > 0` primitives from `index` in the order array.
#[derive(Clone, Copy, Debug)]
#[repr(C)]
struct Node {
    min: [f32; 3],
    index: u32,
    max: [f32; 3],
    count: u32,
}

/// A bounding volume hierarchy over triangles and spheres.
#[derive(Clone, Debug, Default)]
pub struct Bvh {
    nodes: Vec<Node>,
    /// Primitive numbers in leaf order.
    order: Vec<u32>,
    /// Triangle vertices in leaf order (unused slots where spheres sit).
    tris: Vec<[Vec3; 3]>,
    spheres: Vec<Sphere>,
    triangle_count: u32,
    stats: BvhStats,
}

enum BuildNode {
    Leaf {
        bounds: Aabb,
        start: usize,
        count: usize,
    },
    Interior {
        bounds: Aabb,
        children: Box<[BuildNode; 2]>,
    },
}

struct PrimInfo {
    bounds: Aabb,
    centroid: Vec3,
}

const BINS: usize = 16;

/// `a.max(b)` as one instruction: if `a` is NaN the result is `b`.
#[inline(always)]
fn fmax(a: f32, b: f32) -> f32 {
    if a > b {
        a
    } else {
        b
    }
}

/// `a.min(b)` as one instruction: if `a` is NaN the result is `b`.
#[inline(always)]
fn fmin(a: f32, b: f32) -> f32 {
    if a < b {
        a
    } else {
        b
    }
}

/// A ray prepared for slab tests: `t = (p - origin) * inv_dir`.
struct SlabRay {
    inv_dir: Vec3A,
    origin: Vec3A,
}

impl SlabRay {
    fn new(r: &RayPre) -> SlabRay {
        let inv_dir = Vec3A::from(r.inv_dir);
        SlabRay {
            inv_dir,
            origin: Vec3A::from(r.origin),
        }
    }
}

/// Depth after which splits are by median, so that no tree is deeper than this plus 32
/// and the traversal stacks below cannot overflow.
const MEDIAN_DEPTH: usize = 64;
const STACK: usize = 2 * (MEDIAN_DEPTH + 34);

impl Bvh {
    /// Builds the hierarchy. Degenerate triangles (zero area or non-finite) and spheres with
    /// a non-positive or non-finite radius are left out: no ray hits them.
    #[must_use]
    pub fn build(triangles: &[[Vec3; 3]], spheres: &[Sphere], opts: &BuildOptions) -> Bvh {
        let nt = triangles.len();
        let mut info = Vec::with_capacity(nt + spheres.len());
        let mut ids = Vec::with_capacity(nt + spheres.len());
        for (i, t) in triangles.iter().enumerate() {
            let b = Aabb::point(t[0]).extend(t[1]).extend(t[2]);
            let area = (t[1] - t[0]).cross(t[2] - t[0]).length();
            if area > 0.0 && b.min.is_finite() && b.max.is_finite() {
                ids.push(i as u32);
            }
            info.push(PrimInfo {
                bounds: b,
                centroid: b.centroid(),
            });
        }
        for (i, s) in spheres.iter().enumerate() {
            let b = s.bounds();
            if s.radius > 0.0 && b.min.is_finite() && b.max.is_finite() {
                ids.push((nt + i) as u32);
            }
            info.push(PrimInfo {
                bounds: b,
                centroid: s.center,
            });
        }
        let root = if ids.is_empty() {
            None
        } else {
            Some(build_node(&info, &mut ids, 0, 0, opts))
        };
        let mut bvh = Bvh {
            spheres: spheres.to_vec(),
            triangle_count: nt as u32,
            ..Bvh::default()
        };
        if let Some(root) = root {
            bvh.nodes.reserve(2 * ids.len() / 2 + 1);
            let root_area = root_bounds(&root).surface_area().max(f32::MIN_POSITIVE);
            bvh.flatten(&root, 0, root_area, opts.traversal_cost);
        }
        bvh.tris = ids
            .iter()
            .map(|&p| {
                if (p as usize) < nt {
                    triangles[p as usize]
                } else {
                    [Vec3::ZERO; 3]
                }
            })
            .collect();
        bvh.stats.primitives = ids.len();
        bvh.order = ids;
        bvh.stats.nodes = bvh.nodes.len();
        bvh.stats.bytes = bvh.nodes.len() * std::mem::size_of::<Node>()
            + bvh.tris.len() * std::mem::size_of::<[Vec3; 3]>()
            + bvh.order.len() * 4
            + bvh.spheres.len() * std::mem::size_of::<Sphere>();
        bvh
    }

    fn flatten(&mut self, n: &BuildNode, depth: usize, root_area: f32, trav: f32) -> usize {
        let i = self.nodes.len();
        match n {
            BuildNode::Leaf {
                bounds,
                start,
                count,
            } => {
                self.nodes.push(Node {
                    min: bounds.min.to_array(),
                    index: *start as u32,
                    max: bounds.max.to_array(),
                    count: *count as u32,
                });
                self.stats.leaves += 1;
                self.stats.depth = self.stats.depth.max(depth);
                self.stats.max_leaf_size = self.stats.max_leaf_size.max(*count);
                self.stats.sah_cost += bounds.surface_area() / root_area * *count as f32;
            }
            BuildNode::Interior { bounds, children } => {
                self.nodes.push(Node {
                    min: bounds.min.to_array(),
                    index: 0,
                    max: bounds.max.to_array(),
                    count: 0,
                });
                self.stats.sah_cost += bounds.surface_area() / root_area * trav;
                self.flatten(&children[0], depth + 1, root_area, trav);
                let second = self.flatten(&children[1], depth + 1, root_area, trav);
                self.nodes[i].index = second as u32;
            }
        }
        i
    }

    /// Build statistics.
    #[must_use]
    pub fn stats(&self) -> BvhStats {
        self.stats
    }

    /// The bounds of everything in the hierarchy (empty if nothing).
    #[must_use]
    pub fn bounds(&self) -> Aabb {
        self.nodes.first().map_or(Aabb::EMPTY, |n| Aabb {
            min: Vec3::from_array(n.min),
            max: Vec3::from_array(n.max),
        })
    }

    /// Number of triangles the hierarchy was built from (primitive numbers below this are
    /// triangles).
    #[must_use]
    pub fn triangle_count(&self) -> u32 {
        self.triangle_count
    }

    #[inline]
    fn node_hit(n: &Node, r: &SlabRay, tmin: f32, tmax: f32) -> Option<f32> {
        let t0 = (Vec3A::from(n.min) - r.origin) * r.inv_dir;
        let t1 = (Vec3A::from(n.max) - r.origin) * r.inv_dir;
        let lo = t0.min(t1);
        let hi = t0.max(t1);
        // NaN (0 * inf, for a ray in a slab's plane) drops out of these comparisons.
        let near = fmax(fmax(lo.x, lo.y), fmax(lo.z, tmin));
        // Rounding in the slab test may shrink the interval by a few ulps; widening the far
        // end keeps hits on the box faces (Ize, "Robust BVH Ray Traversal", JCGT 2013).
        let far = fmin(fmin(hi.x, hi.y), hi.z) * (1.0 + 2.0 * 3.0 * f32::EPSILON);
        let far = fmin(far, tmax);
        (near <= far).then_some(near)
    }

    #[inline]
    fn leaf_prim(&self, k: usize, r: &RayPre, ray: &Ray, tmin: f32, tmax: f32) -> Option<Hit> {
        let p = self.order[k];
        if p < self.triangle_count {
            intersect_triangle(r, &self.tris[k], tmin, tmax).map(|(t, b1, b2)| Hit {
                t,
                prim: p,
                b1,
                b2,
            })
        } else {
            let s = &self.spheres[(p - self.triangle_count) as usize];
            intersect_sphere(ray, s, tmin, tmax).map(|t| Hit {
                t,
                prim: p,
                b1: 0.0,
                b2: 0.0,
            })
        }
    }

    /// The closest hit with `tmin < t < tmax`.
    #[must_use]
    pub fn intersect(&self, ray: &Ray, tmin: f32, tmax: f32) -> Option<Hit> {
        if self.nodes.is_empty() {
            return None;
        }
        let r = RayPre::new(ray);
        let slab = SlabRay::new(&r);
        let mut best: Option<Hit> = None;
        let mut tmax = tmax;
        let mut stack = [(0u32, 0f32); MEDIAN_DEPTH + 34];
        let mut sp = 0usize;
        let t_root = Self::node_hit(&self.nodes[0], &slab, tmin, tmax)?;
        stack[0] = (0, t_root);
        sp += 1;
        while sp > 0 {
            sp -= 1;
            let (mut i, t_near) = stack[sp];
            if t_near > tmax {
                continue;
            }
            loop {
                let n = &self.nodes[i as usize];
                if n.count > 0 {
                    let start = n.index as usize;
                    for k in start..start + n.count as usize {
                        if let Some(h) = self.leaf_prim(k, &r, ray, tmin, tmax) {
                            tmax = h.t;
                            best = Some(h);
                        }
                    }
                    break;
                }
                let (a, b) = (i + 1, n.index);
                let ha = Self::node_hit(&self.nodes[a as usize], &slab, tmin, tmax);
                let hb = Self::node_hit(&self.nodes[b as usize], &slab, tmin, tmax);
                match (ha, hb) {
                    (Some(ta), Some(tb)) => {
                        let (near, far, tf) = if ta <= tb { (a, b, tb) } else { (b, a, ta) };
                        stack[sp] = (far, tf);
                        sp += 1;
                        i = near;
                    }
                    (Some(_), None) => i = a,
                    (None, Some(_)) => i = b,
                    (None, None) => break,
                }
            }
        }
        best
    }

    /// True if anything lies along the ray with `tmin < t < tmax` (for shadow rays).
    #[must_use]
    pub fn occluded(&self, ray: &Ray, tmin: f32, tmax: f32) -> bool {
        if self.nodes.is_empty() {
            return false;
        }
        let r = RayPre::new(ray);
        let slab = SlabRay::new(&r);
        let mut stack = [0u32; STACK];
        let mut sp = 1usize;
        while sp > 0 {
            sp -= 1;
            let i = stack[sp];
            let n = &self.nodes[i as usize];
            if Self::node_hit(n, &slab, tmin, tmax).is_none() {
                continue;
            }
            if n.count > 0 {
                let start = n.index as usize;
                for k in start..start + n.count as usize {
                    if self.leaf_prim(k, &r, ray, tmin, tmax).is_some() {
                        return true;
                    }
                }
            } else {
                stack[sp] = n.index;
                stack[sp + 1] = i + 1;
                sp += 2;
            }
        }
        false
    }
}

fn root_bounds(n: &BuildNode) -> Aabb {
    match n {
        BuildNode::Leaf { bounds, .. } | BuildNode::Interior { bounds, .. } => *bounds,
    }
}

/// Builds the subtree over `ids`, which start at `offset` in the final order array.
fn build_node(
    info: &[PrimInfo],
    ids: &mut [u32],
    offset: usize,
    depth: usize,
    opts: &BuildOptions,
) -> BuildNode {
    let mut bounds = Aabb::EMPTY;
    let mut cbounds = Aabb::EMPTY;
    for &p in ids.iter() {
        bounds = bounds.union(info[p as usize].bounds);
        cbounds = cbounds.extend(info[p as usize].centroid);
    }
    let n = ids.len();
    let leaf = || BuildNode::Leaf {
        bounds,
        start: offset,
        count: n,
    };
    if n == 1 {
        return leaf();
    }
    // Binned SAH on every axis with a non-degenerate centroid extent.
    let mut best: Option<(f32, usize, usize)> = None; // (cost, axis, split bin)
    let extent = cbounds.extent();
    for axis in 0..3 {
        if extent[axis] <= 0.0 {
            continue;
        }
        let scale = BINS as f32 / extent[axis];
        let bin_of = |p: u32| -> usize {
            let b = ((info[p as usize].centroid[axis] - cbounds.min[axis]) * scale) as usize;
            b.min(BINS - 1)
        };
        let mut counts = [0usize; BINS];
        let mut boxes = [Aabb::EMPTY; BINS];
        for &p in ids.iter() {
            let b = bin_of(p);
            counts[b] += 1;
            boxes[b] = boxes[b].union(info[p as usize].bounds);
        }
        // Sweep from the right, then from the left.
        let mut right_area = [0f32; BINS];
        let mut right_count = [0usize; BINS];
        let (mut acc, mut c) = (Aabb::EMPTY, 0);
        for b in (1..BINS).rev() {
            acc = acc.union(boxes[b]);
            c += counts[b];
            right_area[b] = acc.surface_area();
            right_count[b] = c;
        }
        let (mut acc, mut c) = (Aabb::EMPTY, 0);
        for b in 1..BINS {
            acc = acc.union(boxes[b - 1]);
            c += counts[b - 1];
            if c == 0 || right_count[b] == 0 {
                continue;
            }
            let cost = acc.surface_area() * c as f32 + right_area[b] * right_count[b] as f32;
            if best.is_none_or(|(bc, _, _)| cost < bc) {
                best = Some((cost, axis, b));
            }
        }
    }
    let area = bounds.surface_area().max(f32::MIN_POSITIVE);
    let mid = match best {
        // Past this depth, median splits bound the remaining depth by log2(n).
        Some(_) if depth >= MEDIAN_DEPTH => n / 2,
        Some((cost, axis, split)) => {
            let split_cost = opts.traversal_cost + cost / area;
            if n <= opts.max_leaf && n as f32 <= split_cost {
                return leaf();
            }
            let scale = BINS as f32 / extent[axis];
            let left = partition(ids, |p| {
                let b = ((info[p as usize].centroid[axis] - cbounds.min[axis]) * scale) as usize;
                b.min(BINS - 1) < split
            });
            if left == 0 || left == n {
                n / 2
            } else {
                left
            }
        }
        // Every centroid coincides: nothing separates them.
        None if n <= opts.max_leaf.max(16) => return leaf(),
        None => n / 2,
    };
    let (l, r) = ids.split_at_mut(mid);
    let (a, b) = if n > opts.parallel_threshold {
        rayon::join(
            || build_node(info, l, offset, depth + 1, opts),
            || build_node(info, r, offset + mid, depth + 1, opts),
        )
    } else {
        (
            build_node(info, l, offset, depth + 1, opts),
            build_node(info, r, offset + mid, depth + 1, opts),
        )
    };
    BuildNode::Interior {
        bounds,
        children: Box::new([a, b]),
    }
}

/// Moves the elements satisfying `pred` to the front (stable for neither side); returns
/// how many there are.
fn partition(ids: &mut [u32], pred: impl Fn(u32) -> bool) -> usize {
    let mut i = 0;
    for j in 0..ids.len() {
        if pred(ids[j]) {
            ids.swap(i, j);
            i += 1;
        }
    }
    i
}
