//! The cloth simulation against closed forms and the properties it must have.

use prism_cloth::{parse_scene, Cloth, ClothScene, SpringKind, GRAVITY};
use prism_math::glam::DVec3;

fn scene(nw: usize, nh: usize, orientation: u8, extra: &str, pinned: &str) -> ClothScene {
    let text = format!(
        r#"{{ {extra} "cloth": {{
            "damping": 0.2, "density": 150.0, "ks": 5000.0,
            "enable_structural": true, "enable_shearing": true, "enable_bending": true,
            "orientation": {orientation}, "width": 1, "height": 1,
            "num_width_points": {nw}, "num_height_points": {nh},
            "thickness": 0.0095, "pinned": {pinned} }} }}"#
    );
    parse_scene(&text, "test.json", &[]).unwrap()
}

/// Closed form: structural 2 nw nh - nw - nh, shearing 2 (nw - 1)(nh - 1), bending
/// structural - nw - nh, created in the documented order.
#[test]
fn spring_counts_per_family() {
    for (nw, nh) in [(2, 2), (7, 5), (50, 50)] {
        let c = Cloth::new(&scene(nw, nh, 0, "", "[]"));
        let count = |k| c.springs().iter().filter(|s| s.kind == k).count();
        let structural = 2 * nw * nh - nw - nh;
        assert_eq!(count(SpringKind::Structural), structural);
        assert_eq!(count(SpringKind::Shearing), 2 * (nw - 1) * (nh - 1));
        assert_eq!(count(SpringKind::Bending), structural - nw - nh);
    }
    // Mass (1, 1) of a 3 x 3 grid: structural left and up, shearing up-left and up-right,
    // then nothing two away.
    let c = Cloth::new(&scene(3, 3, 0, "", "[]"));
    let of4: Vec<(u32, SpringKind)> = c
        .springs()
        .iter()
        .filter(|s| s.a == 4)
        .map(|s| (s.b, s.kind))
        .collect();
    assert_eq!(
        of4,
        [
            (3, SpringKind::Structural),
            (1, SpringKind::Structural),
            (0, SpringKind::Shearing),
            (2, SpringKind::Shearing)
        ]
    );
}

/// Closed form (Hooke): a vertical two-column chain hanging from its pinned top row, each
/// vertical spring stretched by the weight below it over ks, is at rest: one step moves no
/// mass by more than rounding. A 2 x 2 grid is a single spring per column.
#[test]
fn hanging_chains_at_rest_obey_hooke() {
    for nh in [2, 5] {
        let mut s = scene(2, nh, 1, "", &format!("[[0, {}], [1, {}]]", nh - 1, nh - 1));
        s.cloth.enable_shearing = false;
        s.cloth.enable_bending = false;
        s.cloth.thickness = 0.0;
        s.cloth.damping = 0.0;
        // Stiff enough that no spring stretches 10% (the length limit stays out of it).
        s.cloth.ks = 50_000.0;
        let mut c = Cloth::new(&s);
        let spacing = 1.0 / (nh - 1) as f64;
        // Flat in z, every structural spring at its length there.
        for p in &mut c.positions {
            p.z = 0.0;
        }
        c.rest_as_now();
        // Row j hangs below row j + 1 by spacing + (j + 1) m g / ks.
        let mg = c.mass * -GRAVITY.y;
        let mut y = 1.0;
        for j in (0..nh - 1).rev() {
            y -= spacing + (j + 1) as f64 * mg / s.cloth.ks;
            for x in 0..2 {
                c.positions[j * 2 + x].y = y;
            }
        }
        c.last.clone_from(&c.positions);
        let before = c.positions.clone();
        c.step();
        for (a, b) in before.iter().zip(&c.positions) {
            assert!((*a - *b).length() < 1e-12, "{a} -> {b}");
        }
    }
}

/// Closed form (Verlet): without springs or collisions, starting at rest, after n steps a
/// mass has fallen g dt² n (n + 1) / 2.
#[test]
fn free_fall_matches_verlet_closed_form() {
    let mut s = scene(4, 4, 0, "", "[]");
    s.cloth.ks = 0.0;
    s.cloth.damping = 0.0;
    s.cloth.thickness = 0.0;
    let mut c = Cloth::new(&s);
    let start = c.positions.clone();
    let n = 90;
    for _ in 0..n {
        c.step();
    }
    let dt = Cloth::dt();
    let drop = GRAVITY * dt * dt * (n * (n + 1) / 2) as f64;
    for (p0, p) in start.iter().zip(&c.positions) {
        assert!(
            (*p - (*p0 + drop)).length() < 1e-12,
            "{p} vs {}",
            *p0 + drop
        );
    }
}

/// Property: with no damping and no collisions, a swinging cloth's energy stays within a
/// few percent of where it started (Verlet is symplectic; the length limit only removes
/// energy).
#[test]
fn energy_is_bounded_without_damping() {
    let mut s = scene(10, 10, 0, "", "[[0, 0], [9, 0]]");
    s.cloth.damping = 0.0;
    s.cloth.thickness = 0.0;
    s.cloth.ks = 50_000.0;
    let mut c = Cloth::new(&s);
    let e0 = c.kinetic_energy() + c.potential_energy();
    let mut worst: f64 = 0.0;
    for _ in 0..60 {
        c.frame();
        let e = c.kinetic_energy() + c.potential_energy();
        worst = worst.max(e - e0);
    }
    // Energy may fall (the length limit) but never grow by more than 1% of the drop scale.
    let scale = c.mass * 9.8 * 100.0;
    assert!(
        worst <= 0.01 * scale,
        "energy grew by {worst} J (scale {scale})"
    );
}

/// Property: a cloth dropped on a sphere above a plane never sinks into either, and pinned
/// masses never move.
#[test]
fn no_penetration_and_pinned_masses_stay() {
    let extra = r#""sphere": {"origin": [0.5, 0.2, 0.5], "radius": 0.2, "friction": 0.3},
                   "plane": {"point": [0, -0.1, 0], "normal": [0, 1, 0], "friction": 0.5},"#;
    let s = scene(20, 20, 0, extra, "[[0, 0]]");
    let mut c = Cloth::new(&s);
    let pin0 = c.positions[0];
    let mut min_sphere = f64::INFINITY;
    let mut min_plane = f64::INFINITY;
    for _ in 0..150 {
        c.frame();
        for (i, p) in c.positions.iter().enumerate() {
            if i != 0 {
                min_sphere = min_sphere.min((*p - DVec3::new(0.5, 0.2, 0.5)).length());
                min_plane = min_plane.min(p.y + 0.1);
            }
        }
        assert_eq!(c.positions[0], pin0);
    }
    assert!(
        min_sphere > 0.2 * 0.98,
        "a mass went {min_sphere} from the centre"
    );
    assert!(
        min_plane >= -1e-9,
        "a mass went {min_plane} below the plane"
    );
}

/// Determinism: one and two threads give the same trajectory, bit for bit.
#[test]
fn identical_on_one_and_two_threads() {
    let s = scene(30, 30, 1, "", "[[0, 29], [29, 29]]");
    let run = |t: usize| {
        prism_testkit::on_threads(t, || {
            let mut c = Cloth::new(&s);
            for _ in 0..20 {
                c.frame();
            }
            c.positions
        })
    };
    assert_eq!(run(1), run(2));
}

/// One time step of `FORMATS.md` §4 written as plainly as the text reads: one loop per
/// step, in order, over every mass or spring, self-collision through a map from exact box
/// keys to masses in index order.
fn plain_step(c: &mut Cloth) {
    let p = c.scene.cloth.clone();
    let dt = 1.0 / 90.0 / 30.0;
    let n = c.positions.len();
    let mut forces = vec![GRAVITY * c.mass; n];
    for s in c.springs() {
        let k = match s.kind {
            SpringKind::Structural if p.enable_structural => p.ks,
            SpringKind::Shearing if p.enable_shearing => p.ks,
            SpringKind::Bending if p.enable_bending => 0.2 * p.ks,
            _ => continue,
        };
        let d = c.positions[s.b as usize] - c.positions[s.a as usize];
        let len = d.length();
        if len == 0.0 {
            continue;
        }
        let f = k * (len - s.rest) * (d / len);
        forces[s.a as usize] += f;
        forces[s.b as usize] -= f;
    }
    for (i, f) in forces.iter().enumerate() {
        if c.pinned[i] {
            continue;
        }
        let x = c.positions[i];
        let next = x + (1.0 - p.damping / 100.0) * (x - c.last[i]) + *f / c.mass * dt * dt;
        c.last[i] = x;
        c.positions[i] = next;
    }
    let w = 3.0 * p.width / p.num_width_points as f64;
    let h = 3.0 * p.height / p.num_height_points as f64;
    let t = w.max(h);
    let key = |q: DVec3| {
        (
            (q.x / w).floor() as i64,
            (q.y / h).floor() as i64,
            (q.z / t).floor() as i64,
        )
    };
    let mut boxes: std::collections::HashMap<_, Vec<usize>> = Default::default();
    for (i, q) in c.positions.iter().enumerate() {
        boxes.entry(key(*q)).or_default().push(i);
    }
    let keys: Vec<_> = c.positions.iter().map(|q| key(*q)).collect();
    for m in 0..n {
        if c.pinned[m] {
            continue;
        }
        let x = c.positions[m];
        let (mut sum, mut count) = (DVec3::ZERO, 0);
        for &q in &boxes[&keys[m]] {
            let d = x - c.positions[q];
            let len = d.length();
            if q != m && len > 0.0 && len < 2.0 * p.thickness {
                sum += (2.0 * p.thickness - len) * (d / len);
                count += 1;
            }
        }
        if count > 0 {
            c.positions[m] = x + sum / f64::from(count) / 30.0;
        }
    }
    for i in 0..n {
        if c.pinned[i] {
            continue;
        }
        let last = c.last[i];
        if let Some(pl) = c.scene.plane {
            let x = c.positions[i];
            let sc = (x - pl.point).dot(pl.normal);
            let sl = (last - pl.point).dot(pl.normal);
            if (sc < 0.0) != (sl < 0.0) {
                let side = if sl < 0.0 { -1.0 } else { 1.0 };
                let target = x - sc * pl.normal + side * 0.0001 * pl.normal;
                c.positions[i] = last + (1.0 - pl.friction) * (target - last);
            }
        }
        if let Some(sp) = c.scene.sphere {
            let x = c.positions[i];
            let d = x - sp.origin;
            if d.length() < sp.radius && d.length() > 0.0 {
                let tangent = sp.origin + sp.radius * (d / d.length());
                c.positions[i] = last + (1.0 - sp.friction) * (tangent - last);
            }
        }
    }
    for s in c.springs().to_vec() {
        let (a, b) = (s.a as usize, s.b as usize);
        let d = c.positions[b] - c.positions[a];
        let len = d.length();
        if len <= 1.1 * s.rest || len == 0.0 || (c.pinned[a] && c.pinned[b]) {
            continue;
        }
        let fix = (len - 1.1 * s.rest) * (d / len);
        if c.pinned[a] {
            c.positions[b] -= fix;
        } else if c.pinned[b] {
            c.positions[a] += fix;
        } else {
            c.positions[a] += 0.5 * fix;
            c.positions[b] -= 0.5 * fix;
        }
    }
}

/// Brute force: the parallel, fused step moves every mass bit for bit as the plain loops
/// of the written algorithm do, over 200 steps of scenes with a sphere, a plane, folding
/// (self-collision and the length limit busy), disabled families, narrow grids and a horizontal
/// cloth.
#[test]
fn step_equals_the_plain_algorithm_bit_for_bit() {
    let cases = [
        scene(
            24,
            24,
            0,
            r#""sphere": {"origin": [0.5, 0.2, 0.5], "radius": 0.3, "friction": 0.3},"#,
            "[]",
        ),
        scene(
            20,
            17,
            0,
            r#""plane": {"point": [0.5, 0.5, 0.5], "normal": [0.2, 1, 0.1], "friction": 0.5},"#,
            "[]",
        ),
        scene(25, 25, 1, "", "[[0, 24], [24, 24]]"),
        scene(18, 21, 0, "", "[[0, 0], [17, 0], [9, 20]]"),
        // Narrow grids: a mass's neighbours two away fall off an edge.
        scene(2, 9, 1, "", "[[0, 8]]"),
        scene(3, 6, 1, "", "[[2, 5]]"),
        scene(9, 2, 1, "", "[[0, 1]]"),
    ];
    let mut shear_off = scene(16, 16, 1, "", "[[0, 15]]");
    shear_off.cloth.enable_shearing = false;
    shear_off.cloth.ks = 900.0;
    // Thick enough that neighbours at rest push each other: self-collision always busy.
    let mut thick = scene(22, 22, 1, "", "[[0, 21], [21, 21]]");
    thick.cloth.thickness = 0.03;
    for s in cases.iter().chain([&shear_off, &thick]) {
        let mut fast = Cloth::new(s);
        let mut plain = fast.clone();
        for step in 0..200 {
            fast.step();
            plain_step(&mut plain);
            assert!(
                fast.positions == plain.positions && fast.last == plain.last,
                "diverged at step {step}"
            );
        }
    }
}
