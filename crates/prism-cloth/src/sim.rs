//! [`Cloth`], the course's mass-spring cloth stepped exactly as `FORMATS.md` §4 writes the
//! algorithm: the grid and its jitter, the three spring families in creation order, forces,
//! Verlet with damping in percent, self-collision by spatial hashing in place, the plane and
//! the sphere, and the sequential 10% length limit; f64 throughout.

use prism_math::glam::DVec3;
use rayon::prelude::*;
use std::time::{Duration, Instant};

use crate::random::{GlibcRand, RAND_MAX};
use crate::scene::{ClothScene, Orientation, PlaneParams, SphereParams};
use crate::springs::{Spring, SpringGrid, SpringKind};

/// Frames per simulated second.
pub const FRAMES_PER_SECOND: f64 = 90.0;
/// Time steps per frame.
pub const STEPS_PER_FRAME: usize = 30;
/// Gravity.
pub const GRAVITY: DVec3 = DVec3::new(0.0, -9.8, 0.0);

/// Wall time spent in each stage of the time step, summed over the steps taken.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StepTimes {
    /// Per stage, in order: the springs' forces; each mass's sum of forces, Verlet and
    /// self-collision box; self-collision and the collision objects; the length limit.
    pub steps: [Duration; 4],
}

impl StepTimes {
    /// The stages' names, in the order of [`StepTimes::steps`].
    pub const NAMES: [&'static str; 4] = [
        "spring forces",
        "verlet",
        "self-collision and objects",
        "length limit",
    ];

    fn add(&mut self, step: usize, since: Instant) -> Instant {
        let now = Instant::now();
        self.steps[step] += now - since;
        now
    }
}

/// The simulated cloth.
#[derive(Clone, Debug)]
pub struct Cloth {
    /// The scene.
    pub scene: ClothScene,
    /// Positions, index `y nw + x`.
    pub positions: Vec<DVec3>,
    /// Positions one step ago.
    pub last: Vec<DVec3>,
    /// Pinned masses.
    pub pinned: Vec<bool>,
    springs: Vec<Spring>,
    /// The mass of every point mass.
    pub mass: f64,
    /// Time spent in each of the five steps so far.
    pub times: StepTimes,
    grid: SpringGrid,
    incident_start: Vec<u32>,
    incident: Vec<u32>,
    sorted: Vec<DVec3>,
    marked: Vec<u64>,
    keys: Vec<BoxKey>,
    cell_start: Vec<u32>,
    cell_fill: Vec<u32>,
    by_cell: Vec<u32>,
}

/// A mass's self-collision box: its exact integer key and its cell in the hash table.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct BoxKey {
    exact: [i64; 3],
    cell: u32,
}

/// The self-collision boxes: their size, and the number of cells (a power of two) of the
/// hash table that groups them.
#[derive(Clone, Copy, Debug)]
struct BoxGrid {
    size: DVec3,
    cells: u32,
}

impl BoxGrid {
    /// The box of a position, `floor(p / size)` per axis.
    #[cfg(test)]
    fn key(&self, p: DVec3) -> BoxKey {
        self.key_of_quotients((p / self.size).to_array())
    }

    /// The box of a position from its quotients `p / size` per axis.
    #[inline(always)]
    fn key_of_quotients(&self, q: [f64; 3]) -> BoxKey {
        let exact = q.map(floor_i64);
        let hash = (exact[0] as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15)
            ^ (exact[1] as u64).wrapping_mul(0xc2b2_ae3d_27d4_eb4f)
            ^ (exact[2] as u64).wrapping_mul(0x1656_67b1_9e37_79f9);
        BoxKey {
            exact,
            cell: (hash >> 40) as u32 & (self.cells - 1),
        }
    }
}

/// Step 4 for one unpinned mass: the plane, then the sphere.
#[inline(always)]
fn collide(
    mut x: DVec3,
    last: DVec3,
    plane: Option<PlaneParams>,
    sphere: Option<SphereParams>,
) -> DVec3 {
    if let Some(p) = plane {
        let sc = (x - p.point).dot(p.normal);
        let sl = (last - p.point).dot(p.normal);
        if (sc < 0.0) != (sl < 0.0) {
            let side = if sl < 0.0 { -1.0 } else { 1.0 };
            let target = x - sc * p.normal + side * 0.0001 * p.normal;
            x = last + (1.0 - p.friction) * (target - last);
        }
    }
    if let Some(s) = sphere {
        let d = x - s.origin;
        let len = d.length();
        if len < s.radius && len > 0.0 {
            let tangent = s.origin + s.radius * (d / len);
            x = last + (1.0 - s.friction) * (tangent - last);
        }
    }
    x
}

/// The three equal thirds of a slice.
fn thirds(s: &mut [f64]) -> [&mut [f64]; 3] {
    let n = s.len() / 3;
    let (a, bc) = s.split_at_mut(n);
    let (b, c) = bc.split_at_mut(n);
    [a, b, c]
}

/// Step 2's constants: Verlet with damping in percent, then the quotients that place a
/// mass in its self-collision box.
#[derive(Clone, Copy)]
struct Verlet {
    dt: f64,
    keep: f64,
    mass: f64,
    size: [f64; 3],
}

impl Verlet {
    /// One row of masses, per axis: from the positions `now`, one step ago `last`, and the
    /// sums of forces `sums`, the next positions into `next` (`now` for a pinned mass),
    /// then `next / size` into `sums`.
    fn row(
        &self,
        now: [&[f64]; 3],
        last: &[DVec3],
        pinned: &[bool],
        sums: [&mut [f64]; 3],
        next: [&mut [f64]; 3],
    ) {
        #[cfg(target_arch = "x86_64")]
        if prism_math::Isa::avx() {
            // SAFETY: the processor has AVX.
            return unsafe { self.row_avx(now, last, pinned, sums, next) };
        }
        self.row_plain(now, last, pinned, sums, next);
    }

    /// [`Verlet::row`] compiled for AVX.
    ///
    /// # Safety
    /// The processor must support AVX.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    unsafe fn row_avx(
        &self,
        now: [&[f64]; 3],
        last: &[DVec3],
        pinned: &[bool],
        sums: [&mut [f64]; 3],
        next: [&mut [f64]; 3],
    ) {
        self.row_plain(now, last, pinned, sums, next);
    }

    /// [`Verlet::row`] as written: `now + keep (now - last) + f / m dt dt`, in that order.
    #[inline(always)]
    fn row_plain(
        &self,
        now: [&[f64]; 3],
        last: &[DVec3],
        pinned: &[bool],
        sums: [&mut [f64]; 3],
        next: [&mut [f64]; 3],
    ) {
        let n = pinned.len();
        let Verlet {
            dt,
            keep,
            mass,
            size,
        } = *self;
        for (i, l) in last[..n].iter().enumerate() {
            (next[0][i], next[1][i], next[2][i]) = (l.x, l.y, l.z);
        }
        let pinned = &pinned[..n];
        for (axis, (sum, next)) in sums.into_iter().zip(next).enumerate() {
            let (now, sum, next, size) =
                (&now[axis][..n], &mut sum[..n], &mut next[..n], size[axis]);
            for i in 0..n {
                let x = now[i];
                let a = sum[i] / mass;
                let moved = x + keep * (x - next[i]) + a * dt * dt;
                let x = if pinned[i] { x } else { moved };
                next[i] = x;
                sum[i] = x / size;
            }
        }
    }
}

/// The margin that keeps a "within the limit" decision made without a square root the
/// exact one's.
const WITHIN: f64 = 1.0 - 1e-9;

/// How far a spring is past 1.1 times its rest length, along it from `a` to `b`; `None`
/// within the limit.
#[inline(always)]
fn stretch(positions: &[DVec3], s: &Spring) -> Option<DVec3> {
    let d = positions[s.b as usize] - positions[s.a as usize];
    let most = 1.1 * s.rest;
    if d.length_squared() < most * most * WITHIN {
        return None;
    }
    let len = d.length();
    if len <= most || len == 0.0 {
        return None;
    }
    Some((len - most) * (d / len))
}

/// Bit `k` set where spring `k` of at most 64 may be over the limit: not decided within it
/// without a square root (a superset of the springs [`stretch`] moves).
#[inline(always)]
fn over_limit(positions: &[DVec3], springs: &[Spring]) -> u64 {
    let mut bits = 0u64;
    for (k, s) in springs.iter().enumerate() {
        let d = positions[s.b as usize] - positions[s.a as usize];
        let most = 1.1 * s.rest;
        bits |= u64::from(d.length_squared() >= most * most * WITHIN) << k;
    }
    bits
}

/// `floor(x)` as an integer, without a library call (saturating far out of range).
#[inline]
fn floor_i64(x: f64) -> i64 {
    let t = x as i64;
    if (t as f64) > x {
        t.saturating_sub(1)
    } else {
        t
    }
}

impl Cloth {
    /// The cloth at rest at the start of the simulation.
    #[must_use]
    pub fn new(scene: &ClothScene) -> Cloth {
        let c = &scene.cloth;
        let (nw, nh) = (c.num_width_points, c.num_height_points);
        let mut rand = GlibcRand::new(1);
        let mut positions = Vec::with_capacity(nw * nh);
        for y in 0..nh {
            for x in 0..nw {
                let px = x as f64 * c.width / (nw - 1) as f64;
                let py = y as f64 * c.height / (nh - 1) as f64;
                positions.push(match c.orientation {
                    Orientation::Horizontal => DVec3::new(px, 1.0, py),
                    Orientation::Vertical => {
                        let z = f64::from(rand.rand()) / f64::from(RAND_MAX) * 2.0 / 1000.0
                            - 1.0 / 1000.0;
                        DVec3::new(px, py, z)
                    }
                });
            }
        }
        let mut pinned = vec![false; nw * nh];
        for &[x, y] in &c.pinned {
            pinned[y * nw + x] = true;
        }
        let mut springs = Vec::new();
        let idx = |x: usize, y: usize| (y * nw + x) as u32;
        let mut add = |a: u32, b: u32, kind| {
            let rest = (positions[a as usize] - positions[b as usize]).length();
            springs.push(Spring { a, b, rest, kind });
        };
        for y in 0..nh {
            for x in 0..nw {
                let me = idx(x, y);
                if x >= 1 {
                    add(me, idx(x - 1, y), SpringKind::Structural);
                }
                if y >= 1 {
                    add(me, idx(x, y - 1), SpringKind::Structural);
                }
                if x >= 1 && y >= 1 {
                    add(me, idx(x - 1, y - 1), SpringKind::Shearing);
                }
                if x + 1 < nw && y >= 1 {
                    add(me, idx(x + 1, y - 1), SpringKind::Shearing);
                }
                if x + 2 < nw {
                    add(me, idx(x + 2, y), SpringKind::Bending);
                }
                if y >= 2 {
                    add(me, idx(x, y - 2), SpringKind::Bending);
                }
            }
        }
        let n = positions.len();
        // Per mass, its springs in creation order: index << 1, and 1 where the mass is `b`.
        let mut incident_start = vec![0u32; n + 1];
        for s in &springs {
            incident_start[s.a as usize + 1] += 1;
            incident_start[s.b as usize + 1] += 1;
        }
        for i in 0..n {
            incident_start[i + 1] += incident_start[i];
        }
        let mut fill = incident_start.clone();
        let mut incident = vec![0u32; 2 * springs.len()];
        for (i, s) in springs.iter().enumerate() {
            for (mass, side) in [(s.a, 0), (s.b, 1)] {
                incident[fill[mass as usize] as usize] = (i as u32) << 1 | side;
                fill[mass as usize] += 1;
            }
        }
        let count = springs.len();
        let k = [
            c.enable_structural.then_some(c.ks),
            c.enable_shearing.then_some(c.ks),
            c.enable_bending.then_some(0.2 * c.ks),
        ];
        let grid = SpringGrid::new(nw, nh, &springs, k);
        Cloth {
            scene: scene.clone(),
            last: positions.clone(),
            positions,
            pinned,
            springs,
            times: StepTimes::default(),
            mass: c.width * c.height * c.density / (nw * nh) as f64,
            grid,
            incident_start,
            incident,
            sorted: vec![DVec3::ZERO; n],
            marked: vec![0; count.div_ceil(64)],
            keys: vec![BoxKey::default(); n],
            cell_start: Vec::new(),
            cell_fill: Vec::new(),
            by_cell: vec![0; n],
        }
    }

    /// The springs, in creation order.
    #[must_use]
    pub fn springs(&self) -> &[Spring] {
        &self.springs
    }

    /// Makes every spring's rest length its length at the current positions: the cloth as
    /// it is now becomes its rest shape.
    pub fn rest_as_now(&mut self) {
        for s in &mut self.springs {
            s.rest = (self.positions[s.a as usize] - self.positions[s.b as usize]).length();
        }
        let k = self.grid.stiffness();
        let c = &self.scene.cloth;
        self.grid = SpringGrid::new(c.num_width_points, c.num_height_points, &self.springs, k);
    }

    /// The time step, `1/90/30` s.
    #[must_use]
    pub fn dt() -> f64 {
        1.0 / FRAMES_PER_SECOND / STEPS_PER_FRAME as f64
    }

    /// One frame: 30 time steps, run from one of rayon's threads so that each step's
    /// parallel passes start without waking the pool from outside.
    pub fn frame(&mut self) {
        rayon::scope(|_| {
            for _ in 0..STEPS_PER_FRAME {
                self.step();
            }
        });
    }

    /// One time step: forces, Verlet, self-collision, collision objects, length limit.
    ///
    /// Work that is independent per spring or per mass runs on rayon, with the steps that
    /// allow it fused into one pass; every sum is still taken in the course's order, so the
    /// result is the same bytes on any number of threads.
    pub fn step(&mut self) {
        let t = Instant::now();
        self.spring_forces();
        let t = self.times.add(0, t);
        self.verlet();
        let t = self.times.add(1, t);
        self.self_collide();
        let t = self.times.add(2, t);
        self.limit_lengths();
        self.times.add(3, t);
    }

    /// Step 1, first half: each spring's force on its own.
    fn spring_forces(&mut self) {
        self.grid.forces(&self.positions);
    }

    /// Step 1, second half, and step 2, per mass: the forces of the mass's springs added
    /// in creation order (the order in which the course's single loop over the springs
    /// adds them, so every sum is bit for bit the sequential one), Verlet with damping in
    /// percent for unpinned masses, then the mass's self-collision box.
    fn verlet(&mut self) {
        let box_grid = self.box_grid();
        let step = Verlet {
            dt: Cloth::dt(),
            keep: 1.0 - self.scene.cloth.damping / 100.0,
            mass: self.mass,
            size: box_grid.size.to_array(),
        };
        let weight = GRAVITY * self.mass;
        let nw = self.scene.cloth.num_width_points;
        let grid = &self.grid;
        self.positions
            .par_chunks_mut(nw)
            .zip(self.last.par_chunks_mut(nw))
            .zip(self.keys.par_chunks_mut(nw).zip(self.pinned.par_chunks(nw)))
            .enumerate()
            .with_min_len(4)
            .for_each_init(
                || vec![0.0; 6 * nw],
                |scratch, (y, ((xs, lasts), (keys, pinned)))| {
                    let (sums, next) = scratch.split_at_mut(3 * nw);
                    let [sx, sy, sz] = thirds(sums);
                    grid.row_sums(y, weight, [&mut *sx, &mut *sy, &mut *sz]);
                    let [nx, ny, nz] = thirds(next);
                    let now = grid.row_positions(y);
                    step.row(
                        now,
                        lasts,
                        pinned,
                        [&mut *sx, &mut *sy, &mut *sz],
                        [&mut *nx, &mut *ny, &mut *nz],
                    );
                    for i in 0..xs.len() {
                        if !pinned[i] {
                            lasts[i] = xs[i];
                            xs[i] = DVec3::new(nx[i], ny[i], nz[i]);
                        }
                        keys[i] = box_grid.key_of_quotients([sx[i], sy[i], sz[i]]);
                    }
                },
            );
    }

    /// The self-collision boxes for this cloth.
    fn box_grid(&self) -> BoxGrid {
        let c = &self.scene.cloth;
        let w = 3.0 * c.width / c.num_width_points as f64;
        let h = 3.0 * c.height / c.num_height_points as f64;
        BoxGrid {
            size: DVec3::new(w, h, w.max(h)),
            cells: self.positions.len().next_power_of_two() as u32,
        }
    }

    /// Step 5: the 10% length limit, sequential over the springs in creation order.
    ///
    /// The springs over the limit at the start of the pass are marked all at once, in a bit
    /// set; the sequential pass then visits, in creation order, only marked springs, and a
    /// correction marks the later springs of the masses it moved. Any other spring sees the
    /// positions it would have seen in a plain loop, within the limit, and a plain loop
    /// would leave it alone: the result is exactly the plain loop's.
    fn limit_lengths(&mut self) {
        let positions = &self.positions;
        let springs = &self.springs;
        self.marked
            .par_iter_mut()
            .enumerate()
            .with_min_len(64)
            .for_each(|(w, word)| {
                let first = w * 64;
                let group = &springs[first..springs.len().min(first + 64)];
                *word = over_limit(positions, group);
            });
        for w in 0..self.marked.len() {
            while self.marked[w] != 0 {
                let k = self.marked[w].trailing_zeros() as usize;
                self.marked[w] &= self.marked[w] - 1;
                let i = w * 64 + k;
                let s = self.springs[i];
                let (a, b) = (s.a as usize, s.b as usize);
                let (pin_a, pin_b) = (self.pinned[a], self.pinned[b]);
                if pin_a && pin_b {
                    continue;
                }
                let Some(fix) = stretch(&self.positions, &s) else {
                    continue;
                };
                if pin_a {
                    self.positions[b] -= fix;
                } else if pin_b {
                    self.positions[a] += fix;
                } else {
                    self.positions[a] += 0.5 * fix;
                    self.positions[b] -= 0.5 * fix;
                }
                for m in [a, b] {
                    let incident = &self.incident
                        [self.incident_start[m] as usize..self.incident_start[m + 1] as usize];
                    // The incident springs are in creation order: mark the later ones.
                    let later = incident.partition_point(|&e| (e >> 1) as usize <= i);
                    for &e in &incident[later..] {
                        let j = (e >> 1) as usize;
                        self.marked[j / 64] |= 1 << (j % 64);
                    }
                }
            }
        }
    }

    /// Steps 3 and 4. Step 3: boxes of `3 width/nw x 3 height/nh x max` from the positions
    /// after Verlet; each unpinned mass in index order moves by the mean of its corrections
    /// / 30, in place. Boxes are found through a hash table of cells filled by a counting
    /// sort (stable, so a cell lists its masses in index order); masses sharing a cell but
    /// not a box are told apart by their exact integer keys. A mass only ever reads masses
    /// of its own box, so cells are worked on in parallel, each in index order: the same
    /// result as one pass over all masses. Step 4 (the plane, then the sphere, per unpinned
    /// mass on its own) follows in the same pass, once a cell is done.
    fn self_collide(&mut self) {
        let c = &self.scene.cloth;
        let two_t = 2.0 * c.thickness;
        let far_enough = two_t * two_t * (1.0 + 1e-9);
        let n = self.positions.len();
        let cells = self.box_grid().cells as usize;
        self.cell_start.clear();
        self.cell_start.resize(cells + 1, 0);
        for key in &self.keys {
            self.cell_start[key.cell as usize + 1] += 1;
        }
        for i in 0..cells {
            self.cell_start[i + 1] += self.cell_start[i];
        }
        self.cell_fill.clear();
        self.cell_fill.extend_from_slice(&self.cell_start[..cells]);
        for (i, key) in self.keys.iter().enumerate() {
            let slot = &mut self.cell_fill[key.cell as usize];
            self.by_cell[*slot as usize] = i as u32;
            *slot += 1;
        }
        for (j, &m) in self.by_cell.iter().enumerate() {
            self.sorted[j] = self.positions[m as usize];
        }
        // Cut the cells into runs of about equal mass counts, each a disjoint slice.
        let runs = 64.min(n);
        let mut pieces = Vec::with_capacity(runs);
        let mut rest: &mut [DVec3] = &mut self.sorted;
        let (mut cell, mut offset) = (0usize, 0usize);
        for r in 1..=runs {
            let goal = n * r / runs;
            let mut end_cell = cell;
            while end_cell < cells && (self.cell_start[end_cell] as usize) < goal {
                end_cell += 1;
            }
            if r == runs {
                end_cell = cells;
            }
            let end = self.cell_start[end_cell] as usize;
            let (piece, tail) = std::mem::take(&mut rest).split_at_mut(end - offset);
            pieces.push((cell, end_cell, offset, piece));
            rest = tail;
            (cell, offset) = (end_cell, end);
        }
        let (cell_start, by_cell, keys, pinned, last) = (
            &self.cell_start,
            &self.by_cell,
            &self.keys,
            &self.pinned,
            &self.last,
        );
        let (plane, sphere) = (self.scene.plane, self.scene.sphere);
        pieces
            .into_par_iter()
            .for_each(|(first, end_cell, offset, piece)| {
                for cell in first..end_cell {
                    let range = cell_start[cell] as usize..cell_start[cell + 1] as usize;
                    let ids = &by_cell[range.clone()];
                    if ids.is_empty() {
                        continue;
                    }
                    let members = &mut piece[range.start - offset..range.end - offset];
                    // Usually a cell holds one box: then no key needs comparing.
                    let box0 = keys[ids[0] as usize].exact;
                    let one_box = ids.iter().all(|&q| keys[q as usize].exact == box0);
                    for j in 0..members.len() {
                        let m = ids[j] as usize;
                        if pinned[m] || members.len() < 2 {
                            continue;
                        }
                        let p = members[j];
                        let mut sum = DVec3::ZERO;
                        let mut count = 0u32;
                        for (i, &q) in members.iter().enumerate() {
                            if i == j || (!one_box && keys[ids[i] as usize].exact != keys[m].exact)
                            {
                                continue;
                            }
                            let d = p - q;
                            // Most neighbours are well outside 2 thickness: decide those
                            // without a square root (the margin keeps the decision exact).
                            if d.length_squared() > far_enough {
                                continue;
                            }
                            let len = d.length();
                            if len > 0.0 && len < two_t {
                                sum += (two_t - len) * (d / len);
                                count += 1;
                            }
                        }
                        if count > 0 {
                            members[j] = p + sum / f64::from(count) / STEPS_PER_FRAME as f64;
                        }
                    }
                    if plane.is_none() && sphere.is_none() {
                        continue;
                    }
                    for (x, &m) in members.iter_mut().zip(ids) {
                        if !pinned[m as usize] {
                            *x = collide(*x, last[m as usize], plane, sphere);
                        }
                    }
                }
            });
        for (sorted, &m) in self.sorted.iter().zip(&self.by_cell) {
            self.positions[m as usize] = *sorted;
        }
    }

    /// True while every position is finite (an unstable time step for the stiffness and
    /// mass makes an explicit integrator diverge).
    #[must_use]
    pub fn is_finite(&self) -> bool {
        self.positions.iter().all(|p| p.is_finite())
    }

    /// Kinetic energy from the last step's displacement, `sum m |x - x_last|² / (2 dt²)`.
    #[must_use]
    pub fn kinetic_energy(&self) -> f64 {
        let dt = Cloth::dt();
        self.positions
            .iter()
            .zip(&self.last)
            .map(|(x, l)| 0.5 * self.mass * (*x - *l).length_squared() / (dt * dt))
            .sum()
    }

    /// Potential energy: gravity above y = 0 plus the enabled springs' `k (l - rest)² / 2`.
    #[must_use]
    pub fn potential_energy(&self) -> f64 {
        let c = &self.scene.cloth;
        let gravity: f64 = self
            .positions
            .iter()
            .map(|p| -GRAVITY.y * self.mass * p.y)
            .sum();
        let springs: f64 = self
            .springs
            .iter()
            .map(|s| {
                let k = match s.kind {
                    SpringKind::Structural if c.enable_structural => c.ks,
                    SpringKind::Shearing if c.enable_shearing => c.ks,
                    SpringKind::Bending if c.enable_bending => 0.2 * c.ks,
                    _ => 0.0,
                };
                let l = (self.positions[s.a as usize] - self.positions[s.b as usize]).length();
                0.5 * k * (l - s.rest).powi(2)
            })
            .sum();
        gravity + springs
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;

    /// Brute force: the hashed self-collision moves every mass exactly as a map from exact
    /// box keys to masses in index order does, on a cloth crumpled into few boxes.
    #[test]
    fn hashed_self_collision_equals_an_exact_map() {
        let text = r#"{"cloth": {"damping": 0.2, "density": 150.0, "ks": 5000.0,
            "enable_structural": true, "enable_shearing": true, "enable_bending": true,
            "orientation": 1, "width": 1, "height": 1, "num_width_points": 40,
            "num_height_points": 40, "thickness": 0.02, "pinned": [[0, 0]]}}"#;
        let scene = crate::parse_scene(text, "t.json", &[]).unwrap();
        let mut a = Cloth::new(&scene);
        // Crumple: squeeze everything into a small ball.
        let mut g = GlibcRand::new(7);
        for p in &mut a.positions {
            let r = |g: &mut GlibcRand| f64::from(g.rand()) / f64::from(RAND_MAX) * 0.1;
            *p = DVec3::new(r(&mut g), r(&mut g), r(&mut g));
        }
        let mut b = a.clone();
        let grid = a.box_grid();
        a.keys = a.positions.iter().map(|p| grid.key(*p)).collect();
        a.self_collide();
        // The reference.
        let c = &b.scene.cloth;
        let w = 3.0 * c.width / c.num_width_points as f64;
        let h = 3.0 * c.height / c.num_height_points as f64;
        let t = w.max(h);
        let two_t = 2.0 * c.thickness;
        let mut boxes: BTreeMap<(i64, i64, i64), Vec<usize>> = BTreeMap::new();
        let key = |p: DVec3| {
            (
                (p.x / w).floor() as i64,
                (p.y / h).floor() as i64,
                (p.z / t).floor() as i64,
            )
        };
        for (i, p) in b.positions.iter().enumerate() {
            boxes.entry(key(*p)).or_default().push(i);
        }
        let mut moved = 0;
        for m in 0..b.positions.len() {
            if b.pinned[m] {
                continue;
            }
            let p = b.positions[m];
            let (mut sum, mut count) = (DVec3::ZERO, 0u32);
            for &q in &boxes[&key(p)] {
                let d = p - b.positions[q];
                let len = d.length();
                if q != m && len > 0.0 && len < two_t {
                    sum += (two_t - len) * (d / len);
                    count += 1;
                }
            }
            if count > 0 {
                b.positions[m] = p + sum / f64::from(count) / STEPS_PER_FRAME as f64;
                moved += 1;
            }
        }
        assert!(moved > 100, "{moved}");
        assert_eq!(a.positions, b.positions);
    }
}
