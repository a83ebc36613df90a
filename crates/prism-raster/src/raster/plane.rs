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
