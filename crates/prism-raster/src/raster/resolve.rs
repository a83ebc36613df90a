//! The box filter: each pixel's samples summed in sample order, a shared pixel's colour
//! added to itself as many times, exactly as a buffer of all samples would be summed.

use super::plane::{Plane, SHARED};

/// Pixels summed side by side, so that their additions overlap.
const LANES: usize = 8;

/// Scratch for [`resolve_row`], kept from row to row.
#[derive(Default)]
pub(super) struct Resolver {
    /// Pixels of the row whose result is the pixel's to the left.
    repeat: Vec<bool>,
    /// Pixels to sum: shared ones and split ones.
    shared: Vec<u32>,
    split: Vec<u32>,
}

impl Resolver {
    /// Writes `convert(sum)` for each pixel `base..base + out.len()` of `plane` into
    /// `out`, where `sum` is the sum of the pixel's samples in sample order. A shared
    /// pixel of the same colour as its left neighbour repeats its result.
    pub(super) fn row<T: Copy>(
        &mut self,
        plane: &Plane,
        base: usize,
        out: &mut [T],
        mut convert: impl FnMut([f32; 4]) -> T,
    ) {
        let w = out.len();
        let n = plane.n;
        self.repeat.clear();
        self.repeat.resize(w, false);
        self.shared.clear();
        self.split.clear();
        let block = &plane.block[base..base + w];
        let px = &plane.px[base..base + w];
        // The previous pixel's colour, when it is shared.
        let (mut before, mut shared_before) = ([0u32; 4], false);
        for x in 0..w {
            if block[x] == SHARED {
                let bits = px[x].map(f32::to_bits);
                let repeat = shared_before && bits == before;
                self.repeat[x] = repeat;
                if !repeat {
                    self.shared.push(x as u32);
                }
                (before, shared_before) = (bits, true);
            } else {
                self.split.push(x as u32);
                shared_before = false;
            }
        }
        for group in self.shared.chunks(LANES) {
            let mut v = [[0f32; 4]; LANES];
            for (v, &x) in v.iter_mut().zip(group) {
                *v = px[x as usize];
            }
            let sums = repeat_sum(v, n);
            for (s, &x) in sums.iter().zip(group) {
                out[x as usize] = convert(*s);
            }
        }
        for group in self.split.chunks(LANES) {
            let mut blocks: [&[[f32; 4]]; LANES] = [&[]; LANES];
            for (b, &x) in blocks.iter_mut().zip(group) {
                let k = block[x as usize] as usize;
                *b = &plane.samples[k * n..(k + 1) * n];
            }
            let mut acc = [[0f32; 4]; LANES];
            for i in 0..n {
                for (a, b) in acc.iter_mut().zip(&blocks).take(group.len()) {
                    *a = add4(*a, b[i]);
                }
            }
            for (s, &x) in acc.iter().zip(group) {
                out[x as usize] = convert(*s);
            }
        }
        let mut last = out[0];
        for (o, &repeat) in out.iter_mut().zip(&self.repeat) {
            if repeat {
                *o = last;
            } else {
                last = *o;
            }
        }
    }
}

/// `v` added to itself in sequence `n` times (from zero), lane by lane.
#[inline(always)]
fn repeat_sum(v: [[f32; 4]; LANES], n: usize) -> [[f32; 4]; LANES] {
    let mut acc = [[0f32; 4]; LANES];
    for _ in 0..n {
        for q in 0..LANES {
            acc[q] = add4(acc[q], v[q]);
        }
    }
    acc
}

#[inline(always)]
fn add4(a: [f32; 4], b: [f32; 4]) -> [f32; 4] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2], a[3] + b[3]]
}
