//! Planes: one layer of a band's samples, kept as one colour per pixel while all of a
//! pixel's samples are equal and as a block of samples once they differ; and [`Cover`],
//! the samples a shape covers on one pixel row, applied to a plane pixel by pixel.

use crate::blend::over;

/// Marks a pixel whose samples all hold its one colour.
pub(super) const SHARED: u32 = u32::MAX;

/// One layer of a band: `pixels` pixels of `n` samples each.
///
/// A pixel is *shared* (every sample equals `px[p]`) or *split* (its samples are block
/// `block[p]`, `n` samples row by row). Every operation gives each sample exactly the value
/// it would get in a buffer of all samples, so a plane is a compressed form of that buffer.
pub(super) struct Plane {
    pub(super) px: Vec<[f32; 4]>,
    pub(super) block: Vec<u32>,
    pub(super) samples: Vec<[f32; 4]>,
    /// The pixel owning each block, or `SHARED` for a free block.
    owner: Vec<u32>,
    free: Vec<u32>,
    pub(super) n: usize,
}

impl Plane {
    /// A plane of shared transparent pixels.
    pub(super) fn new(pixels: usize, n: usize) -> Plane {
        Plane {
            px: vec![[0.0; 4]; pixels],
            block: vec![SHARED; pixels],
            samples: Vec::new(),
            owner: Vec::new(),
            free: Vec::new(),
            n,
        }
    }

    /// Shares every pixel again (their colours are left as they are) and frees all blocks.
    pub(super) fn reset(&mut self) {
        for &p in &self.owner {
            if p != SHARED {
                self.block[p as usize] = SHARED;
            }
        }
        self.owner.clear();
        self.free.clear();
        self.samples.clear();
    }

    /// Sets every sample of the pixels in `range` to `c`.
    pub(super) fn fill(&mut self, range: std::ops::Range<usize>, c: [f32; 4]) {
        if self.block[range.clone()].iter().any(|&b| b != SHARED) {
            for p in range.clone() {
                self.set(p, c);
            }
        } else {
            self.px[range].fill(c);
        }
    }

    /// Composites `src` over every sample of the pixels in `range`.
    pub(super) fn over_range(&mut self, range: std::ops::Range<usize>, src: [f32; 4]) {
        if src[3] >= 1.0 {
            self.fill(range, src);
        } else if src[3] > 0.0 {
            if self.block[range.clone()].iter().any(|&b| b != SHARED) {
                for p in range {
                    self.each(p, |s| over(s, src));
                }
            } else {
                let k = 1.0 - src[3];
                for d in &mut self.px[range] {
                    *d = [
                        src[0] + d[0] * k,
                        src[1] + d[1] * k,
                        src[2] + d[2] * k,
                        src[3] + d[3] * k,
                    ];
                }
            }
        }
    }

    /// Sets every sample of pixel `p` to `c`.
    #[inline]
    pub(super) fn set(&mut self, p: usize, c: [f32; 4]) {
        let b = self.block[p];
        if b != SHARED {
            self.owner[b as usize] = SHARED;
            self.free.push(b);
            self.block[p] = SHARED;
        }
        self.px[p] = c;
    }

    /// Applies `f` to every sample of pixel `p`.
    #[inline]
    pub(super) fn each(&mut self, p: usize, mut f: impl FnMut(&mut [f32; 4])) {
        let b = self.block[p];
        if b == SHARED {
            f(&mut self.px[p]);
        } else {
            let n = self.n;
            self.samples[b as usize * n..(b as usize + 1) * n]
                .iter_mut()
                .for_each(f);
        }
    }

    /// Composites `src` over every sample of pixel `p`.
    #[inline]
    pub(super) fn over(&mut self, p: usize, src: [f32; 4]) {
        if src[3] >= 1.0 {
            self.set(p, src);
        } else if src[3] > 0.0 {
            self.each(p, |s| over(s, src));
        }
    }

    /// The samples of pixel `p`, splitting a shared pixel into copies of its colour.
    #[inline]
    pub(super) fn split(&mut self, p: usize) -> &mut [[f32; 4]] {
        let n = self.n;
        let b = self.block[p];
        let b = if b != SHARED {
            b as usize
        } else {
            let c = self.px[p];
            let b = match self.free.pop() {
                Some(b) => {
                    let b = b as usize;
                    self.samples[b * n..(b + 1) * n].fill(c);
                    self.owner[b] = p as u32;
                    b
                }
                None => {
                    self.owner.push(p as u32);
                    self.samples.resize(self.samples.len() + n, c);
                    self.owner.len() - 1
                }
            };
            self.block[p] = b as u32;
            b
        };
        &mut self.samples[b * n..(b + 1) * n]
    }

    /// Pixel `p`: its one colour when shared, or its samples.
    #[inline]
    pub(super) fn pixel(&self, p: usize) -> Pixel<'_> {
        let b = self.block[p];
        if b == SHARED {
            Pixel::Shared(self.px[p])
        } else {
            let n = self.n;
            Pixel::Split(&self.samples[b as usize * n..(b as usize + 1) * n])
        }
    }

    /// Combines each sample of the pixels in `range` of `src` into the same sample here
    /// with `f(here, src)`.
    pub(super) fn combine(
        &mut self,
        src: &Plane,
        range: std::ops::Range<usize>,
        f: impl Fn(&mut [f32; 4], [f32; 4]),
    ) {
        let shared = |plane: &Plane| plane.block[range.clone()].iter().all(|&b| b == SHARED);
        if shared(src) && shared(self) {
            for (d, s) in self.px[range.clone()].iter_mut().zip(&src.px[range]) {
                f(d, *s);
            }
            return;
        }
        for p in range {
            match src.pixel(p) {
                Pixel::Shared(s) => self.each(p, |d| f(d, s)),
                Pixel::Split(s) => {
                    for (d, s) in self.split(p).iter_mut().zip(s) {
                        f(d, *s);
                    }
                }
            }
        }
    }
}

/// A pixel of a [`Plane`] as read.
pub(super) enum Pixel<'a> {
    /// Every sample holds this colour.
    Shared([f32; 4]),
    /// The samples, row by row.
    Split(&'a [[f32; 4]]),
}

/// The samples one shape covers on the `sub_rows` sample rows of one pixel row: per sample
/// row, sorted disjoint spans `[a, b)` of sample columns.
#[derive(Default)]
pub(super) struct Cover {
    spans: Vec<(usize, usize)>,
    /// `spans[ends[s - 1]..ends[s]]` are sample row `s`'s spans.
    ends: Vec<usize>,
    /// Per pixel of the covered range: samples covered at the ends of spans, and the
    /// running difference of whole pixels covered.
    part: Vec<u32>,
    whole: Vec<i32>,
    cursor: Vec<usize>,
}

impl Cover {
    /// Starts an empty pixel row.
    pub(super) fn clear(&mut self) {
        self.spans.clear();
        self.ends.clear();
    }

    /// Adds a covered span to the current sample row (spans come left to right).
    #[inline]
    pub(super) fn push(&mut self, a: usize, b: usize) {
        if a >= b {
            return;
        }
        let start = self.ends.last().copied().unwrap_or(0);
        let len = self.spans.len();
        match self.spans.last_mut() {
            Some(last) if len > start && last.1 == a => last.1 = b,
            _ => self.spans.push((a, b)),
        }
    }

    /// Ends the current sample row.
    #[inline]
    pub(super) fn end_row(&mut self) {
        self.ends.push(self.spans.len());
    }

    /// Sample rows ended so far.
    pub(super) fn rows(&self) -> usize {
        self.ends.len()
    }

    /// Whether no sample is covered.
    pub(super) fn is_empty(&self) -> bool {
        self.spans.is_empty()
    }

    /// Composites `color(x)` (or `uniform`, when given, the same for every pixel) over
    /// every covered sample of pixel row `row` of `plane` (`width` pixels, `sub_cols`
    /// samples per pixel per sample row): a pixel covered in full is composited once if
    /// shared, a pixel covered in part is split.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn paint(
        &mut self,
        plane: &mut Plane,
        row: usize,
        width: usize,
        sub_cols: usize,
        uniform: Option<[f32; 4]>,
        mut color: impl FnMut(usize) -> [f32; 4],
    ) {
        if self.spans.is_empty() {
            return;
        }
        let sc = sub_cols;
        let n = plane.n;
        let sub_rows = self.ends.len();
        let lo = self.spans.iter().map(|s| s.0).min().unwrap_or(0) / sc;
        let hi = (self.spans.iter().map(|s| s.1).max().unwrap_or(0) - 1) / sc + 1;
        let len = hi - lo;
        self.part.clear();
        self.part.resize(len, 0);
        self.whole.clear();
        self.whole.resize(len + 1, 0);
        for &(a, b) in &self.spans {
            let (pa, pb) = (a / sc, (b - 1) / sc);
            if pa == pb {
                self.part[pa - lo] += (b - a) as u32;
            } else {
                self.part[pa - lo] += ((pa + 1) * sc - a) as u32;
                self.part[pb - lo] += (b - pb * sc) as u32;
                if pb > pa + 1 {
                    self.whole[pa + 1 - lo] += sc as i32;
                    self.whole[pb - lo] -= sc as i32;
                }
            }
        }
        self.cursor.clear();
        self.cursor.push(0);
        self.cursor.extend_from_slice(&self.ends[..sub_rows - 1]);
        // Samples covered per pixel.
        let mut run = 0i32;
        for (part, whole) in self.part.iter_mut().zip(&self.whole) {
            run += whole;
            *part += run as u32;
        }
        let base = row * width;
        let mut i = 0;
        while i < len {
            let covered = self.part[i] as usize;
            if covered == n {
                // A run of pixels covered in full.
                let start = i;
                while i < len && self.part[i] as usize == n {
                    i += 1;
                }
                match uniform {
                    Some(c) => plane.over_range(base + lo + start..base + lo + i, c),
                    None => {
                        for x in lo + start..lo + i {
                            plane.over(base + x, color(x));
                        }
                    }
                }
                continue;
            }
            let x = lo + i;
            i += 1;
            if covered == 0 {
                continue;
            }
            let c = color(x);
            if c[3] <= 0.0 {
                continue;
            }
            let samples = plane.split(base + x);
            let (x0, x1) = (x * sc, (x + 1) * sc);
            for s in 0..sub_rows {
                let end = self.ends[s];
                let mut k = self.cursor[s];
                while k < end && self.spans[k].1 <= x0 {
                    k += 1;
                }
                self.cursor[s] = k;
                while k < end && self.spans[k].0 < x1 {
                    let (a, b) = (self.spans[k].0.max(x0), self.spans[k].1.min(x1));
                    for v in &mut samples[s * sc + a - x0..s * sc + b - x0] {
                        over(v, c);
                    }
                    k += 1;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::resolve::Resolver;
    use super::*;

    /// A deterministic pseudo-random stream (SplitMix64) in [0, 1).
    fn rng(seed: &mut u64) -> f64 {
        *seed = seed.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = *seed;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }

    fn colour(seed: &mut u64) -> [f32; 4] {
        let a = if rng(seed) < 0.3 {
            1.0
        } else {
            rng(seed) as f32
        };
        [
            rng(seed) as f32 * a,
            rng(seed) as f32 * a,
            rng(seed) as f32 * a,
            a,
        ]
    }

    /// A plane beside a buffer of every sample: the same operations on both.
    struct Both {
        plane: Plane,
        full: Vec<[f32; 4]>,
    }

    const W: usize = 11;
    const ROWS: usize = 3;
    const SR: usize = 4;
    const SC: usize = 4;
    const N: usize = SR * SC;

    impl Both {
        fn new() -> Both {
            Both {
                plane: Plane::new(W * ROWS, N),
                full: vec![[0.0; 4]; W * ROWS * N],
            }
        }

        /// Random fills, composites and covers.
        fn step(&mut self, seed: &mut u64, cover: &mut Cover) {
            let row = (rng(seed) * ROWS as f64) as usize;
            let a = (rng(seed) * W as f64) as usize;
            let b = a + (rng(seed) * (W - a) as f64) as usize;
            let range = row * W + a..row * W + b;
            let c = colour(seed);
            match (rng(seed) * 3.0) as usize {
                0 => {
                    self.plane.fill(range.clone(), c);
                    self.full[range.start * N..range.end * N].fill(c);
                }
                1 => {
                    self.plane.over_range(range.clone(), c);
                    self.full[range.start * N..range.end * N]
                        .iter_mut()
                        .for_each(|s| over(s, c));
                }
                _ => {
                    // Random spans on each sample row; a colour per pixel or one for all.
                    cover.clear();
                    let mut covered = [false; SR * W * SC];
                    for s in 0..SR {
                        let mut i = 0;
                        while i < W * SC {
                            let a = i + (rng(seed) * 9.0) as usize;
                            let b = (a + (rng(seed) * 30.0) as usize).min(W * SC);
                            if a < b {
                                cover.push(a, b);
                                covered[s * W * SC + a..s * W * SC + b].fill(true);
                            }
                            i = b.max(a) + 1;
                        }
                        cover.end_row();
                    }
                    let uniform = rng(seed) < 0.5;
                    let per_pixel: Vec<[f32; 4]> = (0..W).map(|_| colour(seed)).collect();
                    let color = |x: usize| if uniform { c } else { per_pixel[x] };
                    cover.paint(&mut self.plane, row, W, SC, uniform.then_some(c), color);
                    for s in 0..SR {
                        for i in 0..W * SC {
                            if covered[s * W * SC + i] {
                                let p = row * W + i / SC;
                                over(&mut self.full[p * N + s * SC + i % SC], color(i / SC));
                            }
                        }
                    }
                }
            }
        }

        fn check(&self) {
            for p in 0..W * ROWS {
                for k in 0..N {
                    let v = match self.plane.pixel(p) {
                        Pixel::Shared(c) => c,
                        Pixel::Split(s) => s[k],
                    };
                    let want = self.full[p * N + k];
                    assert_eq!(v.map(f32::to_bits), want.map(f32::to_bits), "pixel {p}");
                }
            }
        }
    }

    /// Brute force: a plane and a buffer holding every sample, given the same random
    /// fills, composites, covers and layers combined, hold the same samples bit for bit,
    /// and the resolver's sums are those of the buffer's samples added in sample order.
    #[test]
    fn plane_equals_a_buffer_of_every_sample() {
        let mut seed = 7;
        let mut cover = Cover::default();
        let mut resolver = Resolver::default();
        for _ in 0..40 {
            let mut base = Both::new();
            for _ in 0..30 {
                base.step(&mut seed, &mut cover);
                base.check();
                if rng(&mut seed) < 0.2 {
                    // A layer of its own operations, composited at an opacity.
                    let mut layer = Both::new();
                    for _ in 0..5 {
                        layer.step(&mut seed, &mut cover);
                    }
                    let op = rng(&mut seed) as f32;
                    let f = |d: &mut [f32; 4], s: [f32; 4]| over(d, s.map(|v| v * op));
                    base.plane.combine(&layer.plane, 0..W * ROWS, f);
                    for (d, s) in base.full.iter_mut().zip(&layer.full) {
                        f(d, *s);
                    }
                    base.check();
                }
            }
            for row in 0..ROWS {
                let mut sums = vec![[0f32; 4]; W];
                resolver.row(&base.plane, row * W, &mut sums, |s| s);
                for (x, got) in sums.iter().enumerate() {
                    let p = row * W + x;
                    let mut want = [0f32; 4];
                    for s in &base.full[p * N..(p + 1) * N] {
                        for c in 0..4 {
                            want[c] += s[c];
                        }
                    }
                    assert_eq!(got.map(f32::to_bits), want.map(f32::to_bits));
                }
            }
        }
    }
}
