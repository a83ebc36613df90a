//! The BVH against brute force (proptest), its batched queries against its one-ray calls,
//! and watertightness on a closed mesh.

use prism_accel::{
    intersect_sphere, intersect_triangle, BuildOptions, Bvh, Hit, RayPre, Sphere, Split,
};
use prism_math::{Isa, Pcg32, Ray, Vec3};
use proptest::prelude::*;

fn brute_force(tris: &[[Vec3; 3]], spheres: &[Sphere], ray: &Ray, tmax: f32) -> Option<Hit> {
    let pre = RayPre::new(ray);
    let mut best: Option<Hit> = None;
    for (i, t) in tris.iter().enumerate() {
        let lim = best.map_or(tmax, |h| h.t);
        if let Some((t, b1, b2)) = intersect_triangle(&pre, t, 0.0, lim) {
            best = Some(Hit {
                t,
                prim: i as u32,
                b1,
                b2,
            });
        }
    }
    for (i, s) in spheres.iter().enumerate() {
        let lim = best.map_or(tmax, |h| h.t);
        if let Some(t) = intersect_sphere(ray, s, 0.0, lim) {
            best = Some(Hit {
                t,
                prim: (tris.len() + i) as u32,
                b1: 0.0,
                b2: 0.0,
            });
        }
    }
    best
}

fn v3() -> impl Strategy<Value = Vec3> {
    (-10f32..10.0, -10f32..10.0, -10f32..10.0).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

fn scene() -> impl Strategy<Value = (Vec<[Vec3; 3]>, Vec<Sphere>)> {
    (
        prop::collection::vec(
            (v3(), v3(), v3()).prop_map(|(a, b, c)| [a, a + 0.3 * b, a + 0.3 * c]),
            0..300,
        ),
        prop::collection::vec(
            (v3(), 0.05f32..2.0).prop_map(|(c, r)| Sphere {
                center: c,
                radius: r,
            }),
            0..20,
        ),
    )
}

/// Oracle: the one-ray calls. The batched queries' answers for `rays` (closest hits with
/// `1e-3 < t < tmax`, occlusion below each of `ends`) are theirs, bit for bit, on the code
/// paths of every instruction set the processor has (sixteen lanes with AVX-512, eight with
/// AVX2, one ray at a time below).
fn check_batches(bvh: &Bvh, rays: &[Ray], ends: &[f32], tmax: f32) -> Result<(), TestCaseError> {
    let bits = |h: Option<Hit>| h.map(|h| (h.t.to_bits(), h.prim, h.b1.to_bits(), h.b2.to_bits()));
    for isa in [Isa::Sse, Isa::Avx2, Isa::Avx512] {
        let mut hits = vec![None; rays.len()];
        bvh.intersect_batch_on(isa, rays, 1e-3, tmax, &mut hits);
        let mut blocked = vec![false; rays.len()];
        bvh.occluded_batch_on(isa, rays, 1e-3, ends, &mut blocked);
        for (i, ray) in rays.iter().enumerate() {
            prop_assert_eq!(
                bits(hits[i]),
                bits(bvh.intersect(ray, 1e-3, tmax)),
                "{:?}, ray {}",
                isa,
                i
            );
            prop_assert_eq!(blocked[i], bvh.occluded(ray, 1e-3, ends[i]), "{:?}", isa);
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Oracle: brute force over every primitive, in number order. The closest hit is the
    /// same hit, the lowest-numbered where several primitives are hit at one distance;
    /// any-hit agrees with closest-hit.
    #[test]
    fn closest_hit_equals_brute_force(
        (tris, spheres) in scene(),
        rays in prop::collection::vec((v3(), v3()), 64),
        max_leaf in 1usize..9,
    ) {
        let opts = BuildOptions { max_leaf, parallel_threshold: 64, ..BuildOptions::default() };
        let bvh = Bvh::build(&tris, &spheres, &opts);
        for (o, d) in rays {
            if d.length() < 1e-3 {
                continue;
            }
            let ray = Ray::new(o, d);
            let want = brute_force(&tris, &spheres, &ray, f32::INFINITY);
            let got = bvh.intersect(&ray, 0.0, f32::INFINITY);
            let bits = |h: Option<Hit>| h.map(|h| (h.t.to_bits(), h.prim, h.b1.to_bits(), h.b2.to_bits()));
            prop_assert_eq!(bits(got), bits(want), "brute force {:?} but BVH {:?}", want, got);
            prop_assert_eq!(bvh.occluded(&ray, 0.0, f32::INFINITY), want.is_some());
            if let Some(w) = want {
                prop_assert!(!bvh.occluded(&ray, 0.0, w.t * 0.999));
            }
        }
    }

    /// Oracle: the one-ray calls. A batch gets exactly their hits and occlusions, ray by
    /// ray, with each shadow ray's own end.
    #[test]
    fn batches_equal_single_rays(
        (tris, spheres) in scene(),
        rays in prop::collection::vec((v3(), v3(), 0.5f32..20.0), 0..70),
    ) {
        let bvh = Bvh::build(&tris, &spheres, &BuildOptions::default());
        let (rays, ends): (Vec<Ray>, Vec<f32>) =
            rays.into_iter().map(|(o, d, t)| (Ray::new(o, d), t)).unzip();
        check_batches(&bvh, &rays, &ends, 15.0)?;
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// Oracle: the one-ray calls, on hierarchies small enough for the batched queries to test
    /// every primitive on lanes. The scenes hold a quad split on its diagonal, whose edge the
    /// rays through grid points meet exactly (edge functions of zero), and a triangle twice
    /// (two hits at one distance): every hit and occlusion is the one-ray call's, bit for bit.
    #[test]
    fn small_scene_batches_equal_single_rays(
        tris in prop::collection::vec(
            (v3(), v3(), v3()).prop_map(|(a, b, c)| [a, a + 0.5 * b, a + 0.5 * c]),
            0..14,
        ),
        spheres in prop::collection::vec(
            (v3(), 0.05f32..3.0).prop_map(|(c, r)| Sphere { center: c, radius: r }),
            0..5,
        ),
        rays in prop::collection::vec((v3(), v3(), 0.5f32..20.0, 0u8..4), 1..90),
    ) {
        let mut tris = tris;
        let quad = [Vec3::new(-2.0, -2.0, 0.0), Vec3::new(2.0, -2.0, 0.0), Vec3::new(2.0, 2.0, 0.0)];
        tris.push(quad);
        tris.push([quad[0], quad[2], Vec3::new(-2.0, 2.0, 0.0)]);
        tris.push(quad);
        let bvh = Bvh::build(&tris, &spheres, &BuildOptions::default());
        let (rays, ends): (Vec<Ray>, Vec<f32>) = rays
            .into_iter()
            .map(|(o, d, t, kind)| {
                let ray = match kind {
                    // Through a grid point of the quad's diagonal.
                    0 => Ray::new(o.round(), Vec3::new(0.0, 0.0, 0.0) - o.round()),
                    // Axis-aligned, from a grid point.
                    1 => Ray::new(o.round(), [Vec3::X, -Vec3::Y, Vec3::Z][(t as usize) % 3]),
                    _ => Ray::new(o, d),
                };
                (ray, t)
            })
            .unzip();
        check_batches(&bvh, &rays, &ends, 15.0)?;
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Oracle: the one-ray calls, in a room: ten large triangles (its walls, which the build
    /// lifts into the root and the batched queries test on lanes) around a cluster of small
    /// ones and spheres (which rays that reach them still traverse, from the one child of
    /// the root they enter, or from the root). Rays start inside, some at grid points and
    /// axis-aligned (edges met exactly), some aimed at the cluster; every hit and occlusion
    /// is the one-ray call's, bit for bit.
    #[test]
    fn room_batches_equal_single_rays(
        small in prop::collection::vec(
            (v3(), v3(), v3()).prop_map(|(a, b, c)| {
                let a = a * 0.2;
                [a, a + 0.05 * b, a + 0.05 * c]
            }),
            30..200,
        ),
        spheres in prop::collection::vec(
            (v3(), 0.05f32..0.5).prop_map(|(c, r)| Sphere { center: c * 0.2, radius: r }),
            0..4,
        ),
        rays in prop::collection::vec((v3(), v3(), 0.5f32..30.0, 0u8..4), 1..120),
    ) {
        let mut tris = room_walls();
        tris.extend(small);
        let bvh = Bvh::build(&tris, &spheres, &BuildOptions::default());
        let (rays, ends): (Vec<Ray>, Vec<f32>) = rays
            .into_iter()
            .map(|(o, d, t, kind)| {
                let ray = match kind {
                    0 => Ray::new(o.round() * 0.5, d),
                    1 => Ray::new(o.round() * 0.5, [Vec3::X, -Vec3::Y, Vec3::Z][(t as usize) % 3]),
                    // At a point of the cluster: through one or several of the root's
                    // children that hold it.
                    2 => Ray::new(o * 0.9, d * 0.2 - o * 0.9),
                    _ => Ray::new(o * 0.9, d),
                };
                (ray, t)
            })
            .unzip();
        check_batches(&bvh, &rays, &ends, f32::INFINITY)?;
    }
}

/// The walls of a room, the cube from -10 to 10 open at `z = 10`: five squares, each two
/// triangles.
fn room_walls() -> Vec<[Vec3; 3]> {
    let c = |x: f32, y: f32, z: f32| Vec3::new(x, y, z) * 10.0;
    let quad = |a: Vec3, b: Vec3, cc: Vec3, d: Vec3| [[a, b, cc], [a, cc, d]];
    [
        quad(
            c(-1., -1., -1.),
            c(1., -1., -1.),
            c(1., -1., 1.),
            c(-1., -1., 1.),
        ),
        quad(
            c(-1., 1., -1.),
            c(-1., 1., 1.),
            c(1., 1., 1.),
            c(1., 1., -1.),
        ),
        quad(
            c(-1., -1., -1.),
            c(-1., 1., -1.),
            c(1., 1., -1.),
            c(1., -1., -1.),
        ),
        quad(
            c(-1., -1., -1.),
            c(-1., -1., 1.),
            c(-1., 1., 1.),
            c(-1., 1., -1.),
        ),
        quad(
            c(1., -1., -1.),
            c(1., 1., -1.),
            c(1., 1., 1.),
            c(1., -1., 1.),
        ),
    ]
    .into_iter()
    .flatten()
    .collect()
}

/// Oracle: the one-ray calls. Rays from inside the room aimed at points of the edges of its
/// open side, where an edge function of a wall is often exactly zero in single precision and
/// the one-ray test decides in double precision, sometimes against the hit: the batched
/// queries answer as it does, closest hits and occlusion alike.
#[test]
fn rays_through_open_edges_answer_as_single_rays() {
    let mut tris = room_walls();
    let mut rng = Pcg32::new(1, 1);
    let mut unit = || Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
    for i in 0..100 {
        let a = unit() * 4.0 + Vec3::splat(1.0);
        tris.push([
            a,
            a + Vec3::X * 0.5,
            a + Vec3::new(0.0, 0.5, 0.1 * i as f32),
        ]);
    }
    let bvh = Bvh::build(&tris, &[], &BuildOptions::default());
    let rays: Vec<Ray> = (0..20_000)
        .map(|k| {
            let o = unit() * 18.0 - Vec3::splat(9.0);
            let s = unit().x * 20.0 - 10.0;
            let edge = [
                Vec3::new(s, 10.0, 10.0),
                Vec3::new(s, -10.0, 10.0),
                Vec3::new(10.0, s, 10.0),
                Vec3::new(-10.0, s, 10.0),
            ];
            Ray::new(o, edge[k % 4] - o)
        })
        .collect();
    let ends = vec![5.0; rays.len()];
    // The edge is at t = 1: some rays miss it by the one-ray test and leave the room.
    let leave = rays.iter().filter(|r| !bvh.occluded(r, 1e-3, 5.0)).count();
    assert!(leave > 500, "{leave} rays leave the room");
    check_batches(&bvh, &rays, &ends, 5.0).unwrap();
}

/// A closed triangulated sphere of radius 3.7 about the origin: its vertices and triangles.
fn sphere_mesh() -> (Vec<Vec3>, Vec<[Vec3; 3]>) {
    let mut verts = vec![];
    let mut tris = vec![];
    let (nu, nv) = (64, 32);
    for j in 0..=nv {
        for i in 0..nu {
            let th = std::f32::consts::PI * j as f32 / nv as f32;
            let ph = 2.0 * std::f32::consts::PI * i as f32 / nu as f32;
            verts.push(Vec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()) * 3.7);
        }
    }
    for j in 0..nv {
        for i in 0..nu {
            let a = j * nu + i;
            let b = j * nu + (i + 1) % nu;
            let (c, d) = (a + nu, b + nu);
            tris.push([verts[a], verts[b], verts[d]]);
            tris.push([verts[a], verts[d], verts[c]]);
        }
    }
    (verts, tris)
}

/// Property: watertightness. Rays from the centre of a closed triangulated sphere, aimed at
/// its vertices and edge midpoints (where tests that are not watertight leak), always hit.
#[test]
fn closed_mesh_is_watertight() {
    let (verts, tris) = sphere_mesh();
    let bvh = Bvh::build(&tris, &[], &BuildOptions::default());
    let centre = Vec3::new(1e-3, -2e-3, 0.5e-3);
    let mut rng = Pcg32::new(3, 4);
    let mut targets: Vec<Vec3> = verts.clone();
    for t in &tris {
        targets.push((t[0] + t[1]) * 0.5);
        targets.push((t[1] + t[2]) * 0.5);
        targets.push((t[2] + t[0]) * 0.5);
    }
    for p in targets {
        for _ in 0..4 {
            let o = centre + Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 1e-4;
            let ray = Ray::new(o, p - o);
            assert!(
                bvh.intersect(&ray, 0.0, f32::INFINITY).is_some(),
                "leak towards {p}"
            );
        }
    }
}

/// Oracle: the one-ray calls, on a mesh whose root holds no leaf (so no list: the batched
/// closest-hit query walks two rays at a time through the whole tree). Batches of every
/// size from 0 to 9 and a long one, rays from inside and outside the sphere, some aimed at
/// vertices (shared edges, hits at one distance): every hit is the one-ray call's, bit for
/// bit, on every instruction set.
#[test]
fn mesh_batches_equal_single_rays() {
    let (verts, mut tris) = sphere_mesh();
    let mut rng = Pcg32::new(5, 6);
    let mut r = || Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - Vec3::ONE;
    // Small triangles inside, so that walks differ in length.
    for _ in 0..500 {
        let a = r() * 3.0;
        tris.push([a, a + r() * 0.2, a + r() * 0.2]);
    }
    let bvh = Bvh::build(&tris, &[], &BuildOptions::default());
    let rays: Vec<Ray> = (0..1500)
        .map(|i| match i % 3 {
            0 => Ray::new(r() * 2.0, r()),
            1 => Ray::new(r() * 9.0, verts[i % verts.len()] - r() * 9.0),
            _ => Ray::new(Vec3::ZERO, verts[i % verts.len()]),
        })
        .collect();
    let ends: Vec<f32> = (0..rays.len()).map(|i| 1.0 + (i % 7) as f32).collect();
    let mut start = 0;
    for len in (0..10).chain([rays.len()]) {
        let end = (start + len).min(rays.len());
        let (rays, ends) = if len == rays.len() {
            (&rays[..], &ends[..])
        } else {
            (&rays[start..end], &ends[start..end])
        };
        check_batches(&bvh, rays, ends, f32::INFINITY).unwrap();
        check_batches(&bvh, rays, ends, 4.0).unwrap();
        start = end;
    }
}

/// Oracle: the one-ray calls, on batches that mix groups of coherent rays (a pinhole
/// camera's: one origin, one octant, which the batched query walks as packets) with loose
/// rays, in runs of every length, in a closed mesh alone and inside a room (whose walls the
/// batched query tests on lanes before the packet walks the rest): every hit is the one-ray
/// call's, bit for bit, on every instruction set. Some camera rays pass through the
/// sphere's vertices exactly.
#[test]
fn camera_batches_equal_single_rays() {
    let (verts, mut tris) = sphere_mesh();
    let mut rng = Pcg32::new(7, 8);
    let mut r = || Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - Vec3::ONE;
    for _ in 0..300 {
        let a = r() * 3.0;
        tris.push([a, a + r() * 0.3, a + r() * 0.3]);
    }
    let spheres = [Sphere {
        center: Vec3::new(0.5, -0.5, 1.0),
        radius: 0.4,
    }];
    let mut room = tris.clone();
    let c = |x: f32, y: f32, z: f32| Vec3::new(x, y, z) * 12.0;
    for [a, b, cc, d] in [
        [
            c(-1., -1., -1.),
            c(1., -1., -1.),
            c(1., -1., 1.),
            c(-1., -1., 1.),
        ],
        [
            c(-1., 1., -1.),
            c(-1., 1., 1.),
            c(1., 1., 1.),
            c(1., 1., -1.),
        ],
        [
            c(-1., -1., -1.),
            c(-1., 1., -1.),
            c(1., 1., -1.),
            c(1., -1., -1.),
        ],
        [
            c(-1., -1., -1.),
            c(-1., -1., 1.),
            c(-1., 1., 1.),
            c(-1., 1., -1.),
        ],
    ] {
        room.push([a, b, cc]);
        room.push([a, cc, d]);
    }
    for tris in [tris, room] {
        camera_batches(&verts, &tris, &spheres, &mut r);
    }
}

fn camera_batches(
    verts: &[Vec3],
    tris: &[[Vec3; 3]],
    spheres: &[Sphere],
    r: &mut impl FnMut() -> Vec3,
) {
    let bvh = Bvh::build(tris, spheres, &BuildOptions::default());
    let mut rays = vec![];
    for k in 0..40 {
        let eye = if k % 2 == 0 {
            r() * 0.5
        } else {
            r() * 2.0 + Vec3::new(0.0, 0.0, 9.0)
        };
        let aim = r() * 2.0;
        // A camera's rays, in scanline order, sixteen or eight to a row.
        for i in 0..32 {
            let pixel = Vec3::new((i % 16) as f32, (i / 16) as f32, 0.0) * 0.01;
            rays.push(Ray::new(eye, aim + pixel - eye));
        }
        // Rays through vertices from one origin.
        for i in 0..16 {
            rays.push(Ray::new(eye, verts[(k * 37 + i) % verts.len()] - eye));
        }
        // A camera looking past the sphere, at the walls.
        for i in 0..16 {
            rays.push(Ray::new(
                eye,
                aim * 4.0 + Vec3::new(i as f32, 0.0, 0.0) * 0.3 - eye,
            ));
        }
        // Loose rays between the groups.
        for _ in 0..k % 5 {
            rays.push(Ray::new(r() * 4.0, r()));
        }
    }
    let ends: Vec<f32> = (0..rays.len()).map(|i| 2.0 + (i % 5) as f32).collect();
    for skip in [0, 3, 8] {
        check_batches(&bvh, &rays[skip..], &ends[skip..], f32::INFINITY).unwrap();
        check_batches(&bvh, &rays[skip..], &ends[skip..], 6.0).unwrap();
    }
}

/// Property: the hierarchy is the same whatever the thread count (same statistics and the
/// same hits), and statistics are consistent.
/// Property: degenerate triangles (zero area, or a non-finite corner) are left out alike by
/// the parallel build and the serial one: the same layout, byte for byte in its debug form,
/// over only the others.
#[test]
fn parallel_build_leaves_out_degenerate_triangles_as_the_serial_one() {
    let mut rng = Pcg32::new(5, 3);
    let mut r = || Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 10.0;
    let tris: Vec<[Vec3; 3]> = (0..3000)
        .map(|i| {
            let a = r();
            match i % 7 {
                0 => [a, a, a + Vec3::X],
                1 => [a, a + Vec3::new(f32::NAN, 0.0, 0.0), a + Vec3::Y],
                _ => [a, a + r() * 0.05, a + r() * 0.05],
            }
        })
        .collect();
    let serial = Bvh::build(&tris, &[], &BuildOptions::default());
    let parallel = Bvh::build(
        &tris,
        &[],
        &BuildOptions {
            parallel_threshold: 64,
            ..BuildOptions::default()
        },
    );
    assert_eq!(serial.stats().primitives, 3000 - 2 * 3000usize.div_ceil(7));
    assert_eq!(format!("{serial:?}"), format!("{parallel:?}"));
}

#[test]
fn build_is_deterministic_and_stats_add_up() {
    let mut rng = Pcg32::new(9, 1);
    let mut r = || Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 10.0;
    let tris: Vec<[Vec3; 3]> = (0..20_000)
        .map(|_| {
            let a = r();
            [a, a + r() * 0.05, a + r() * 0.05]
        })
        .collect();
    let opts = BuildOptions {
        parallel_threshold: 256,
        ..BuildOptions::default()
    };
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let a = one.install(|| Bvh::build(&tris, &[], &opts));
    let b = Bvh::build(&tris, &[], &opts);
    assert_eq!(a.stats(), b.stats());
    // The whole layout: nodes, packs and leaves, byte for byte in their debug form.
    assert_eq!(format!("{a:?}"), format!("{b:?}"));
    let s = a.stats();
    // An 8-wide tree: every node holds at most eight children.
    assert!(s.nodes < s.leaves && 7 * s.nodes + 1 >= s.leaves);
    assert_eq!(s.primitives, 20_000);
    assert!(s.depth < 64 && s.sah_cost > 0.0);
    for k in 0..1000 {
        let o = Vec3::splat(-1.0);
        let d = Vec3::new(1.0, (k % 37) as f32 / 37.0, (k % 11) as f32 / 11.0);
        assert_eq!(
            a.intersect(&Ray::new(o, d), 0.0, f32::INFINITY),
            b.intersect(&Ray::new(o, d), 0.0, f32::INFINITY)
        );
    }
}

/// Oracle: brute force. Axis-aligned squares on an integer grid give flat boxes, and
/// axis-aligned rays (zero and negative-zero direction components) starting on box planes
/// make slab distances of 0 * inf; the BVH must still find exactly the brute-force hits.
#[test]
fn axis_aligned_rays_on_box_planes_match_brute_force() {
    let mut tris = vec![];
    for i in 0..6 {
        for j in 0..6 {
            let (x, y) = (i as f32, j as f32);
            let z = ((i * 7 + j * 3) % 5) as f32;
            let quad = [
                Vec3::new(x, y, z),
                Vec3::new(x + 1.0, y, z),
                Vec3::new(x + 1.0, y + 1.0, z),
                Vec3::new(x, y + 1.0, z),
            ];
            // Alternate the plane the square lies in.
            let quad = quad.map(|p| match (i + j) % 3 {
                0 => p,
                1 => Vec3::new(p.z, p.x, p.y),
                _ => Vec3::new(p.y, p.z, p.x),
            });
            tris.push([quad[0], quad[1], quad[2]]);
            tris.push([quad[0], quad[2], quad[3]]);
        }
    }
    let bvh = Bvh::build(
        &tris,
        &[],
        &BuildOptions {
            max_leaf: 2,
            ..BuildOptions::default()
        },
    );
    let dirs = [
        Vec3::X,
        -Vec3::X,
        Vec3::Y,
        -Vec3::Y,
        Vec3::Z,
        -Vec3::Z,
        Vec3::new(1.0, -0.0, 0.0),
        Vec3::new(-0.0, 1.0, -0.0),
        Vec3::new(0.0, -0.0, -1.0),
    ];
    let mut checked = 0;
    for a in -1..8 {
        for b in -1..8 {
            for c in -1..8 {
                let o = Vec3::new(a as f32 * 0.5, b as f32, c as f32 * 0.75);
                for d in dirs {
                    let ray = Ray::new(o, d);
                    let want = brute_force(&tris, &[], &ray, f32::INFINITY);
                    let got = bvh.intersect(&ray, 0.0, f32::INFINITY);
                    assert_eq!(want, got, "ray {o} {d}");
                    assert_eq!(bvh.occluded(&ray, 0.0, f32::INFINITY), want.is_some());
                    checked += usize::from(want.is_some());
                }
            }
        }
    }
    assert!(checked > 500, "only {checked} rays hit");
}

/// Property: a ray's hit is a pure function of the ray and the primitives, whatever the
/// hierarchy's shape. Oracle: brute force, which keeps the first primitive in number order
/// at the nearest distance. A grid of squares at several heights, each triangle listed twice
/// (primitives `i` and `i + n` are one triangle, so every hit is a tie), walked by rays
/// aimed at grid points and edge midpoints (ties between neighbours too), gives the
/// lower-numbered hit, one ray at a time and in batches on every instruction set, in
/// hierarchies of leaves of 1 to 16 primitives.
#[test]
fn ties_go_to_the_lowest_primitive_whatever_the_hierarchy() {
    let mut grid = vec![];
    for i in 0..12 {
        for j in 0..12 {
            let (x, y, z) = (i as f32, j as f32, ((i + 2 * j) % 3) as f32);
            let p = [
                Vec3::new(x, y, z),
                Vec3::new(x + 1.0, y, z),
                Vec3::new(x + 1.0, y + 1.0, z),
                Vec3::new(x, y + 1.0, z),
            ];
            grid.push([p[0], p[1], p[2]]);
            grid.push([p[0], p[2], p[3]]);
        }
    }
    let n = grid.len() as u32;
    let tris: Vec<_> = grid.iter().chain(&grid).copied().collect();
    let mut rng = Pcg32::new(21, 4);
    let mut rays = vec![];
    for _ in 0..3000 {
        let at = |rng: &mut Pcg32| (rng.next_u32() % 25) as f32 * 0.5;
        let target = Vec3::new(at(&mut rng), at(&mut rng), (rng.next_u32() % 3) as f32);
        let o = Vec3::new(
            at(&mut rng),
            at(&mut rng),
            6.0 + (rng.next_u32() % 4) as f32,
        );
        rays.push(Ray::new(o, target - o));
    }
    let bits = |h: Option<Hit>| h.map(|h| (h.t.to_bits(), h.prim, h.b1.to_bits(), h.b2.to_bits()));
    let want: Vec<_> = rays
        .iter()
        .map(|r| bits(brute_force(&tris, &[], r, f32::INFINITY)))
        .collect();
    let hits = want.iter().flatten().count();
    assert!(hits > 2000, "{hits} hits");
    assert!(want.iter().flatten().all(|h| h.1 < n));
    for max_leaf in [1, 2, 3, 4, 8, 16] {
        let opts = BuildOptions {
            max_leaf,
            ..BuildOptions::default()
        };
        let bvh = Bvh::build(&tris, &[], &opts);
        for (ray, want) in rays.iter().zip(&want) {
            assert_eq!(
                bits(bvh.intersect(ray, 0.0, f32::INFINITY)),
                *want,
                "leaves of {max_leaf}"
            );
        }
        for isa in [Isa::Sse, Isa::Avx2, Isa::Avx512] {
            let mut got = vec![None; rays.len()];
            bvh.intersect_batch_on(isa, &rays, 0.0, f32::INFINITY, &mut got);
            let got: Vec<_> = got.into_iter().map(bits).collect();
            assert_eq!(got, want, "leaves of {max_leaf}, {isa:?}");
        }
    }
}

/// Oracle: brute force, for trees split at the centroid median (the Delft template's
/// scheme); and the SAH tree's expected cost is the lower, as the heuristic intends.
#[test]
fn median_split_trees_find_the_brute_force_hits_at_a_higher_cost() {
    let (_, sphere) = sphere_mesh();
    let mut rng = Pcg32::new(3, 7);
    let mut r = || Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
    let mut tris = sphere;
    for _ in 0..2000 {
        let a = r() * 8.0 - Vec3::splat(4.0);
        tris.push([a, a + r() * 0.3, a + r() * 0.3]);
    }
    let spheres = [Sphere {
        center: Vec3::new(0.5, 0.2, 0.1),
        radius: 0.7,
    }];
    let median = BuildOptions {
        split: Split::Median,
        parallel_threshold: 512,
        ..BuildOptions::default()
    };
    let m = Bvh::build(&tris, &spheres, &median);
    let s = Bvh::build(&tris, &spheres, &BuildOptions::default());
    assert_eq!(m.stats().primitives, s.stats().primitives);
    assert!(
        s.stats().sah_cost < m.stats().sah_cost,
        "SAH {} against median {}",
        s.stats().sah_cost,
        m.stats().sah_cost
    );
    // Half on each side: a median tree of n primitives is about log2(n / leaf) deep.
    assert!(m.stats().depth <= 12, "depth {}", m.stats().depth);
    let bits = |h: Option<Hit>| h.map(|h| (h.t.to_bits(), h.prim, h.b1.to_bits(), h.b2.to_bits()));
    for _ in 0..2000 {
        let o = r() * 10.0 - Vec3::splat(5.0);
        let d = r() - Vec3::splat(0.5);
        let ray = Ray::new(o, d);
        let want = brute_force(&tris, &spheres, &ray, f32::INFINITY);
        assert_eq!(bits(m.intersect(&ray, 0.0, f32::INFINITY)), bits(want));
        assert_eq!(m.occluded(&ray, 0.0, f32::INFINITY), want.is_some());
    }
}
