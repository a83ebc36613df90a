//! The springs: [`Spring`] and its [`SpringKind`], and [`SpringGrid`], their forces laid
//! out by family on the cloth's grid, so that a mass's sum of forces reads fixed neighbours
//! in creation order and runs four masses to a vector, each lane the scalar sum's
//! operations in the scalar sum's order.

use prism_math::glam::DVec3;

/// The three spring families.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SpringKind {
    /// To the neighbours left and above.
    Structural,
    /// To the diagonal neighbours above.
    Shearing,
    /// To the masses two away, left and above.
    Bending,
}

/// A spring between masses `a` and `b`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spring {
    /// First mass.
    pub a: u32,
    /// Second mass.
    pub b: u32,
    /// Length at construction.
    pub rest: f64,
    /// Family.
    pub kind: SpringKind,
}

/// The six spring families in the order a mass creates its springs: structural left and
/// up, shearing up-left and up-right, bending two right and two up.
const FAMILIES: usize = 6;

/// Each family's second mass from its first (the creating mass), in grid steps `(x, y)`.
const REACH: [(isize, isize); FAMILIES] = [(-1, 0), (0, -1), (-1, -1), (1, -1), (2, 0), (0, -2)];

/// Zero columns on each side of a row of forces: a mass's neighbours two columns away
/// read zeros past the cloth's edge.
const PAD: usize = 2;

/// Zero rows after the last row of forces: a mass reads the forces of springs created two
/// rows further on.
const PAD_ROWS: usize = 2;

/// The springs of a `nw x nh` cloth by family: per row and family, the rest lengths, and
/// after [`SpringGrid::forces`], the force of each spring on the mass that created it (zero
/// where the spring does not exist or its family is disabled).
#[derive(Clone, Debug)]
pub(crate) struct SpringGrid {
    nw: usize,
    nh: usize,
    /// A padded row's length, `nw + 2 PAD`.
    width: usize,
    /// Stiffness per kind of spring, `None` when the kind is disabled.
    kinds: [Option<f64>; 3],
    /// Stiffness per family.
    k: [Option<f64>; FAMILIES],
    /// Rest lengths, `[row][family][width]`.
    rest: Vec<f64>,
    /// Positions by axis, `[row][axis][nw]`.
    soa: Vec<f64>,
    /// Forces, `[row][family][axis][width]`, with [`PAD_ROWS`] rows of zeros after the last.
    forces: Vec<f64>,
}

/// The family of a spring created by a mass at `(x, y)` towards `(bx, by)`.
fn family(dx: isize, dy: isize) -> usize {
    REACH
        .iter()
        .position(|&r| r == (dx, dy))
        .expect("every spring of the grid is one of the six families")
}

impl SpringGrid {
    /// The grid of `springs` (in creation order, as [`crate::Cloth::new`] makes them) on a
    /// `nw x nh` cloth, with the stiffness of each kind (`None` when disabled).
    pub(crate) fn new(nw: usize, nh: usize, springs: &[Spring], k: [Option<f64>; 3]) -> Self {
        let width = nw + 2 * PAD;
        let mut rest = vec![0.0; nh * FAMILIES * width];
        for s in springs {
            let (a, b) = (s.a as usize, s.b as usize);
            let (ax, ay) = ((a % nw) as isize, (a / nw) as isize);
            let (bx, by) = ((b % nw) as isize, (b / nw) as isize);
            let f = family(bx - ax, by - ay);
            rest[(ay as usize * FAMILIES + f) * width + PAD + ax as usize] = s.rest;
        }
        let kind = |f: usize| match f {
            0 | 1 => SpringKind::Structural,
            2 | 3 => SpringKind::Shearing,
            _ => SpringKind::Bending,
        };
        SpringGrid {
            nw,
            nh,
            width,
            kinds: k,
            k: std::array::from_fn(|f| k[kind(f) as usize]),
            rest,
            soa: vec![0.0; nw * nh * 3],
            forces: vec![0.0; (nh + PAD_ROWS) * FAMILIES * 3 * width],
        }
    }

    /// The positions of row `y` by axis, as the last [`SpringGrid::forces`] read them.
    pub(crate) fn row_positions(&self, y: usize) -> [&[f64]; 3] {
        let row = &self.soa[3 * self.nw * y..][..3 * self.nw];
        let (x, yz) = row.split_at(self.nw);
        let (y, z) = yz.split_at(self.nw);
        [x, y, z]
    }

    /// The stiffness per kind of spring it was made with.
    pub(crate) fn stiffness(&self) -> [Option<f64>; 3] {
        self.kinds
    }

    /// Every spring's force on the mass that created it, `k (|pb - pa| - rest) (pb - pa) /
    /// |pb - pa|` (zero for a spring of length zero), from the positions (index `y nw + x`).
    pub(crate) fn forces(&mut self, positions: &[DVec3]) {
        use rayon::prelude::*;
        let nw = self.nw;
        self.soa
            .par_chunks_mut(3 * nw)
            .zip(positions.par_chunks(nw))
            .with_min_len(8)
            .for_each(|(row, p)| {
                let (x, yz) = row.split_at_mut(nw);
                let (y, z) = yz.split_at_mut(nw);
                for (i, p) in p.iter().enumerate() {
                    (x[i], y[i], z[i]) = (p.x, p.y, p.z);
                }
            });
        let rows = 3 * FAMILIES * self.width;
        let (soa, rest, k) = (&self.soa, &self.rest, self.k);
        let width = self.width;
        self.forces[..self.nh * rows]
            .par_chunks_mut(rows)
            .enumerate()
            .with_min_len(4)
            .for_each(|(y, out)| {
                let rest = &rest[y * FAMILIES * width..][..FAMILIES * width];
                row_forces(soa, nw, y, &k, rest, out);
            });
    }

    /// The sum of forces on each mass of row `y`, per axis into `sum` (`nw` each), starting
    /// from `weight`: the forces of the mass's springs added (as the first mass) or
    /// subtracted (as the second) in creation order, as the course's single loop over the
    /// springs adds them. Adding a zero (a spring that does not exist) leaves a sum
    /// unchanged: it starts at the weight, whose zero components are +0, so it is never -0.
    pub(crate) fn row_sums(&self, y: usize, weight: DVec3, sum: [&mut [f64]; 3]) {
        #[cfg(target_arch = "x86_64")]
        if prism_math::Isa::avx() {
            // SAFETY: the processor has AVX.
            return unsafe { self.row_sums_avx(y, weight, sum) };
        }
        self.row_sums_plain(y, weight, sum);
    }

    /// [`SpringGrid::row_sums`] compiled for AVX.
    ///
    /// # Safety
    /// The processor must support AVX.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    unsafe fn row_sums_avx(&self, y: usize, weight: DVec3, sum: [&mut [f64]; 3]) {
        self.row_sums_plain(y, weight, sum);
    }

    /// [`SpringGrid::row_sums`] as written.
    #[inline(always)]
    fn row_sums_plain<'a>(&'a self, y: usize, weight: DVec3, sum: [&mut [f64]; 3]) {
        let (nw, width) = (self.nw, self.width);
        let rows = 3 * FAMILIES * width;
        let here = &self.forces[y * rows..][..rows];
        let next = &self.forces[(y + 1) * rows..][..rows];
        let after = &self.forces[(y + 2) * rows..][..rows];
        for (axis, (out, w)) in sum.into_iter().zip(weight.to_array()).enumerate() {
            // A family's forces in `row`, from column `x + shift - PAD` for mass `x`.
            let at = |row: &'a [f64], f: usize, shift: usize| -> &'a [f64] {
                &row[(f * 3 + axis) * width + shift..][..nw]
            };
            // Creators in index order: two left (bending), the mass itself (its six
            // families), one right (structural), then the row below: up-right shearing
            // from the left, structural from below, up-left shearing from the right, and
            // bending from two rows below.
            let from_left2 = at(here, 4, PAD - 2);
            let own = [0, 1, 2, 3, 4, 5].map(|f| at(here, f, PAD));
            let right = at(here, 0, PAD + 1);
            let below_left = at(next, 3, PAD - 1);
            let below = at(next, 1, PAD);
            let below_right = at(next, 2, PAD + 1);
            let below2 = at(after, 5, PAD);
            let out = &mut out[..nw];
            for x in 0..nw {
                let mut f = w;
                f -= from_left2[x];
                f += own[0][x];
                f += own[1][x];
                f += own[2][x];
                f += own[3][x];
                f += own[4][x];
                f += own[5][x];
                f -= right[x];
                f -= below_left[x];
                f -= below[x];
                f -= below_right[x];
                f -= below2[x];
                out[x] = f;
            }
        }
    }
}

/// The forces of the springs that the masses of row `y` create, into `out`
/// (`[family][axis][width]`), from the positions by axis and the row's rest lengths.
fn row_forces(
    soa: &[f64],
    nw: usize,
    y: usize,
    k: &[Option<f64>; FAMILIES],
    rest: &[f64],
    out: &mut [f64],
) {
    #[cfg(target_arch = "x86_64")]
    if prism_math::Isa::avx() {
        // SAFETY: the processor has AVX.
        return unsafe { row_forces_avx(soa, nw, y, k, rest, out) };
    }
    row_forces_plain(soa, nw, y, k, rest, out);
}

/// [`row_forces`] compiled for AVX.
///
/// # Safety
/// The processor must support AVX.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
unsafe fn row_forces_avx(
    soa: &[f64],
    nw: usize,
    y: usize,
    k: &[Option<f64>; FAMILIES],
    rest: &[f64],
    out: &mut [f64],
) {
    row_forces_plain(soa, nw, y, k, rest, out);
}

/// [`row_forces`] as written: per family, over the columns where its springs exist.
#[inline(always)]
fn row_forces_plain(
    soa: &[f64],
    nw: usize,
    y: usize,
    k: &[Option<f64>; FAMILIES],
    rest: &[f64],
    out: &mut [f64],
) {
    let width = nw + 2 * PAD;
    let axis = |row: usize, a: usize| &soa[(row * 3 + a) * nw..][..nw];
    for (f, &(dx, dy)) in REACH.iter().enumerate() {
        let Some(k) = k[f] else { continue };
        let Some(by) = y.checked_add_signed(dy) else {
            continue;
        };
        let lo = (-dx).max(0) as usize;
        let hi = nw.saturating_sub(dx.max(0) as usize);
        if lo >= hi {
            continue;
        }
        let n = hi - lo;
        let b0 = (lo as isize + dx) as usize;
        let (ax, ay, az) = (
            &axis(y, 0)[lo..hi],
            &axis(y, 1)[lo..hi],
            &axis(y, 2)[lo..hi],
        );
        let (bx, by_, bz) = (
            &axis(by, 0)[b0..b0 + n],
            &axis(by, 1)[b0..b0 + n],
            &axis(by, 2)[b0..b0 + n],
        );
        let rest = &rest[f * width + PAD + lo..][..n];
        let family = &mut out[f * 3 * width..][..3 * width];
        let (ox, oyz) = family.split_at_mut(width);
        let (oy, oz) = oyz.split_at_mut(width);
        let (ox, oy, oz) = (
            &mut ox[PAD + lo..][..n],
            &mut oy[PAD + lo..][..n],
            &mut oz[PAD + lo..][..n],
        );
        for i in 0..n {
            let (dx, dy, dz) = (bx[i] - ax[i], by_[i] - ay[i], bz[i] - az[i]);
            let len = (dx * dx + dy * dy + dz * dz).sqrt();
            let scale = k * (len - rest[i]);
            let live = len != 0.0;
            ox[i] = if live { scale * (dx / len) } else { 0.0 };
            oy[i] = if live { scale * (dy / len) } else { 0.0 };
            oz[i] = if live { scale * (dz / len) } else { 0.0 };
        }
    }
}
