//! [`Cloth`], the course's mass-spring cloth stepped exactly as `FORMATS.md` §4 writes the
//! algorithm: the grid and its jitter, the three spring families in creation order, forces,
//! Verlet with damping in percent, self-collision by spatial hashing in place, the plane and
//! the sphere, and the sequential 10% length limit; f64 throughout.

use prism_math::glam::DVec3;

use crate::random::{GlibcRand, RAND_MAX};
use crate::scene::{ClothScene, Orientation};

/// Frames per simulated second.
pub const FRAMES_PER_SECOND: f64 = 90.0;
/// Time steps per frame.
pub const STEPS_PER_FRAME: usize = 30;
/// Gravity.
pub const GRAVITY: DVec3 = DVec3::new(0.0, -9.8, 0.0);

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
    /// Springs in creation order.
    pub springs: Vec<Spring>,
    /// The mass of every point mass.
    pub mass: f64,
    forces: Vec<DVec3>,
    keys: Vec<(i64, i64, i64, u32)>,
    cell_start: Vec<u32>,
    cell_fill: Vec<u32>,
    by_cell: Vec<u32>,
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
        Cloth {
            scene: scene.clone(),
            last: positions.clone(),
            positions,
            pinned,
            springs,
            mass: c.width * c.height * c.density / (nw * nh) as f64,
            forces: vec![DVec3::ZERO; n],
            keys: Vec::with_capacity(n),
            cell_start: Vec::new(),
            cell_fill: Vec::new(),
            by_cell: Vec::new(),
        }
    }

    /// The time step, `1/90/30` s.
    #[must_use]
    pub fn dt() -> f64 {
        1.0 / FRAMES_PER_SECOND / STEPS_PER_FRAME as f64
    }

    /// One frame: 30 time steps.
    pub fn frame(&mut self) {
        for _ in 0..STEPS_PER_FRAME {
            self.step();
        }
    }

    /// One time step: forces, Verlet, self-collision, collision objects, length limit.
    pub fn step(&mut self) {
        let c = &self.scene.cloth;
        let dt = Cloth::dt();
        // 1. Forces.
        let weight = GRAVITY * self.mass;
        self.forces.iter_mut().for_each(|f| *f = weight);
        for s in &self.springs {
            let k = match s.kind {
                SpringKind::Structural if c.enable_structural => c.ks,
                SpringKind::Shearing if c.enable_shearing => c.ks,
                SpringKind::Bending if c.enable_bending => 0.2 * c.ks,
                _ => continue,
            };
            let (pa, pb) = (self.positions[s.a as usize], self.positions[s.b as usize]);
            let d = pb - pa;
            let len = d.length();
            if len == 0.0 {
                continue;
            }
            let f = k * (len - s.rest) * (d / len);
            self.forces[s.a as usize] += f;
            self.forces[s.b as usize] -= f;
        }
        // 2. Verlet.
        let keep = 1.0 - c.damping / 100.0;
        for i in 0..self.positions.len() {
            if self.pinned[i] {
                continue;
            }
            let x = self.positions[i];
            let a = self.forces[i] / self.mass;
            let next = x + keep * (x - self.last[i]) + a * dt * dt;
            self.last[i] = x;
            self.positions[i] = next;
        }
        // 3. Self-collision.
        self.self_collide();
        // 4. Collision objects: the plane before the sphere.
        let (plane, sphere) = (self.scene.plane, self.scene.sphere);
        for i in 0..self.positions.len() {
            if self.pinned[i] {
                continue;
            }
            let last = self.last[i];
            if let Some(p) = plane {
                let x = self.positions[i];
                let sc = (x - p.point).dot(p.normal);
                let sl = (last - p.point).dot(p.normal);
                if (sc < 0.0) != (sl < 0.0) {
                    let side = if sl < 0.0 { -1.0 } else { 1.0 };
                    let target = x - sc * p.normal + side * 0.0001 * p.normal;
                    self.positions[i] = last + (1.0 - p.friction) * (target - last);
                }
            }
            if let Some(s) = sphere {
                let x = self.positions[i];
                let d = x - s.origin;
                let len = d.length();
                if len < s.radius && len > 0.0 {
                    let tangent = s.origin + s.radius * (d / len);
                    self.positions[i] = last + (1.0 - s.friction) * (tangent - last);
                }
            }
        }
        // 5. Length limit, sequential in creation order.
        for s in &self.springs {
            let (a, b) = (s.a as usize, s.b as usize);
            let (pin_a, pin_b) = (self.pinned[a], self.pinned[b]);
            if pin_a && pin_b {
                continue;
            }
            let d = self.positions[b] - self.positions[a];
            let most = 1.1 * s.rest;
            // Most springs are well inside the limit: decide those without a square root
            // (the margin keeps the decision the exact one's).
            if d.length_squared() < most * most * (1.0 - 1e-9) {
                continue;
            }
            let len = d.length();
            if len <= most || len == 0.0 {
                continue;
            }
            let fix = (len - most) * (d / len);
            if pin_a {
                self.positions[b] -= fix;
            } else if pin_b {
                self.positions[a] += fix;
            } else {
                self.positions[a] += 0.5 * fix;
                self.positions[b] -= 0.5 * fix;
            }
        }
    }

    /// Step 3: boxes of `3 width/nw x 3 height/nh x max` from the positions after Verlet;
    /// each unpinned mass in index order moves by the mean of its corrections / 30, in
    /// place. Boxes are found through a hash table of cells filled by a counting sort
    /// (stable, so a cell lists its masses in index order); masses sharing a cell but not a
    /// box are told apart by their exact integer keys.
    fn self_collide(&mut self) {
        let c = &self.scene.cloth;
        let w = 3.0 * c.width / c.num_width_points as f64;
        let h = 3.0 * c.height / c.num_height_points as f64;
        let t = w.max(h);
        let two_t = 2.0 * c.thickness;
        let far_enough = two_t * two_t * (1.0 + 1e-9);
        let n = self.positions.len();
        let cells = (2 * n).next_power_of_two();
        self.keys.clear();
        self.keys.extend(self.positions.iter().map(|p| {
            let k = (floor_i64(p.x / w), floor_i64(p.y / h), floor_i64(p.z / t));
            let hash = (k.0 as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15)
                ^ (k.1 as u64).wrapping_mul(0xc2b2_ae3d_27d4_eb4f)
                ^ (k.2 as u64).wrapping_mul(0x1656_67b1_9e37_79f9);
            (k.0, k.1, k.2, (hash >> 40) as u32 & (cells as u32 - 1))
        }));
        self.cell_start.clear();
        self.cell_start.resize(cells + 1, 0);
        for k in &self.keys {
            self.cell_start[k.3 as usize + 1] += 1;
        }
        for i in 0..cells {
            self.cell_start[i + 1] += self.cell_start[i];
        }
        self.cell_fill.clear();
        self.cell_fill.extend_from_slice(&self.cell_start[..cells]);
        self.by_cell.clear();
        self.by_cell.resize(n, 0);
        for (i, k) in self.keys.iter().enumerate() {
            let slot = &mut self.cell_fill[k.3 as usize];
            self.by_cell[*slot as usize] = i as u32;
            *slot += 1;
        }
        for m in 0..n {
            if self.pinned[m] {
                continue;
            }
            let p = self.positions[m];
            let km = self.keys[m];
            let cell = km.3 as usize;
            let mut sum = DVec3::ZERO;
            let mut count = 0u32;
            for &q in
                &self.by_cell[self.cell_start[cell] as usize..self.cell_start[cell + 1] as usize]
            {
                let q = q as usize;
                let kq = self.keys[q];
                if q == m || (kq.0, kq.1, kq.2) != (km.0, km.1, km.2) {
                    continue;
                }
                let d = p - self.positions[q];
                // Most neighbours are well outside 2 thickness: decide those without a square
                // root (the margin keeps the decision the exact one's).
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
                self.positions[m] = p + sum / f64::from(count) / STEPS_PER_FRAME as f64;
            }
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
