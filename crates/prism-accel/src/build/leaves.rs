//! Leaves: each placed by the collapse (a reference that holds up to seven packs itself, else
//! an entry of the leaf table) and its triangles packed in fours, in parallel.

use std::mem::MaybeUninit;

use prism_math::{prefetch, Vec3};
use rayon::prelude::*;

use super::node::BuildNode;
use super::options::MAX_LEAF_REF;
use crate::layout::tri4::Tri4;
use crate::layout::{Bvh, LeafRec, LEAF, LOW_BITS, PACKS_SHIFT};

/// A leaf placed by the collapse, whose triangles are packed afterwards (in parallel): its
/// range in the build order and its first pack.
pub(crate) struct LeafJob {
    pub(crate) start: usize,
    pub(crate) count: usize,
    pub(crate) pack_start: usize,
    pub(crate) packs: usize,
}

/// How far ahead, in primitives, leaf packing prefetches triangles.
pub(crate) const PACK_AHEAD: usize = 16;

impl Bvh {
    /// Places a leaf: its packs of four triangles (filled by [`Bvh::pack_leaves`]) and its
    /// spheres. Returns its reference.
    pub(crate) fn plan_leaf(
        &mut self,
        n: &BuildNode,
        order: &[u32],
        jobs: &mut Vec<LeafJob>,
    ) -> u32 {
        let BuildNode::Leaf { start, count, .. } = *n else {
            unreachable!("only leaves are stored as leaves")
        };
        let nt = self.triangle_count;
        let prims = &order[start..start + count];
        let nt_leaf = prims.iter().filter(|&&p| p < nt).count();
        let pack_start = jobs.last().map_or(0, |j| j.pack_start + j.packs);
        let rec = LeafRec {
            pack_start: pack_start as u32,
            sphere_start: self.leaf_spheres.len() as u32,
            packs: nt_leaf.div_ceil(4) as u16,
            spheres: (count - nt_leaf) as u16,
        };
        jobs.push(LeafJob {
            start,
            count,
            pack_start,
            packs: usize::from(rec.packs),
        });
        assert!(
            pack_start + usize::from(rec.packs) <= LOW_BITS as usize
                && self.leaves.len() < LOW_BITS as usize,
            "BVH over 2^30 triangles"
        );
        if rec.spheres == 0 && rec.packs < 8 {
            return LEAF | u32::from(rec.packs) << PACKS_SHIFT | rec.pack_start;
        }
        self.leaf_spheres
            .extend(prims.iter().copied().filter(|&p| p >= nt));
        self.leaves.push(rec);
        LEAF | (self.leaves.len() - 1) as u32
    }

    /// Fills the triangle packs of the leaves the collapse placed, in parallel for large
    /// hierarchies (each leaf writes only its own packs, so the result is the same).
    pub(crate) fn pack_leaves(
        &mut self,
        jobs: &[LeafJob],
        triangles: &[[Vec3; 3]],
        order: &[u32],
        parallel_threshold: usize,
    ) {
        let total = jobs.last().map_or(0, |j| j.pack_start + j.packs);
        // Each pack is written once, by its leaf's job (in parallel, so that the first
        // touch of the memory is shared too).
        let mut packs: Vec<Tri4> = Vec::with_capacity(total);
        let nt = self.triangle_count;
        let fill = |job: &LeafJob, out: &mut [MaybeUninit<Tri4>]| {
            let mut tris = [([Vec3::ZERO; 3], 0u32); MAX_LEAF_REF];
            // The build order visits triangles out of the mesh's order: start loading those
            // a few leaves ahead, so that the misses overlap.
            let ahead = (job.start + PACK_AHEAD).min(order.len());
            for &p in &order[ahead..(ahead + job.count).min(order.len())] {
                prefetch(triangles.as_ptr().wrapping_add(p as usize));
            }
            let mut n = 0;
            for &p in order[job.start..job.start + job.count]
                .iter()
                .filter(|&&p| p < nt)
            {
                tris[n] = (triangles[p as usize], p);
                n += 1;
            }
            assert_eq!(
                n.div_ceil(4),
                out.len(),
                "a leaf's packs hold its triangles"
            );
            for (pack, four) in out.iter_mut().zip(tris[..n].chunks(4)) {
                pack.write(Tri4::new(four));
            }
        };
        let mut rest = &mut packs.spare_capacity_mut()[..total];
        let mut outs = Vec::with_capacity(jobs.len());
        for job in jobs {
            let (out, tail) = std::mem::take(&mut rest).split_at_mut(job.packs);
            outs.push(out);
            rest = tail;
        }
        if order.len() > parallel_threshold {
            jobs.par_iter()
                .zip(outs)
                .with_min_len(256)
                .for_each(|(job, out)| fill(job, out));
        } else {
            for (job, out) in jobs.iter().zip(outs) {
                fill(job, out);
            }
        }
        // SAFETY: the jobs' ranges tile `0..total` (each starts where the last ended) and
        // each job wrote every pack of its range (asserted above).
        unsafe { packs.set_len(total) };
        self.packs = packs;
    }
}
