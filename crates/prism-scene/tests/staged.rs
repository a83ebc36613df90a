//! The staged COLLADA files (`../shared/assets/{meshedit,pathtracer}/dae`): every one loads,
//! its meshes build as halfedge meshes with the topology `FORMATS.md` records, and the
//! course's before/after files are reproduced by prism's flip, split and collapse.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use prism_math::glam::DVec3;
use prism_mesh::{HalfedgeMesh, PolyMesh, VertexId};
use prism_scene::{read_collada, Shape, UpAxis};
use prism_testkit::shared_assets;

fn dae_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            dae_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "dae") {
            out.push(p);
        }
    }
}

fn load(rel: &str) -> PolyMesh {
    read_collada(&shared_assets().join(rel))
        .unwrap()
        .world_mesh(false)
        .unwrap()
}

#[test]
fn every_staged_file_loads_and_every_mesh_is_a_manifold() {
    let mut files = Vec::new();
    for d in ["meshedit/dae", "pathtracer/dae"] {
        dae_files(&shared_assets().join(d), &mut files);
    }
    files.sort();
    assert_eq!(files.len(), 35, "{files:?}");
    for f in &files {
        let c = read_collada(f).unwrap_or_else(|e| panic!("{e}"));
        assert!(c.warnings.is_empty(), "{}: {:?}", f.display(), c.warnings);
        let mut meshes = 0;
        for g in &c.geometries {
            if let Shape::Mesh(m) = &g.shape {
                meshes += 1;
                assert!(m.mesh.is_triangle_mesh());
                HalfedgeMesh::from_polymesh(&m.mesh)
                    .unwrap_or_else(|e| panic!("{}: {}: {e}", f.display(), g.id));
            }
        }
        assert!(meshes > 0, "{}", f.display());
        assert!(!c.nodes.is_empty(), "{}", f.display());
        let pathtracer = f.components().any(|c| c.as_os_str() == "pathtracer");
        if pathtracer {
            assert_eq!(c.up_axis, UpAxis::Z, "{}", f.display());
        }
    }
}

/// Oracle: the topology facts recorded in `FORMATS.md` (boundary edges, Euler characteristic).
#[test]
fn meshedit_topology_matches_the_recorded_facts() {
    let cases: &[(&str, i64, usize)] = &[
        ("beetle.dae", -9, 586),
        ("teapot.dae", 0, 0),
        ("torus/input.dae", 0, 0),
        ("peter.dae", 4, 0),
        ("cow.dae", 2, 0),
        ("cube.dae", 2, 0),
        ("icosahedron/input.dae", 2, 0),
        ("quadball.dae", 2, 0),
        ("weird.dae", 2, 0),
    ];
    for &(name, chi, boundary) in cases {
        let h = HalfedgeMesh::from_polymesh(&load(&format!("meshedit/dae/{name}"))).unwrap();
        h.validate().unwrap();
        let b = (0..h.edge_count())
            .filter(|&e| h.is_boundary_edge(prism_mesh::EdgeId(e as u32)))
            .count();
        assert_eq!((h.euler_characteristic(), b), (chi, boundary), "{name}");
    }
}

/// Oriented faces of `a` renumbered by `a`'s vertex -> nearest vertex of `b` (within 1e-5:
/// the course's files store single precision), each rotated to start at its smallest index,
/// so that two meshes compare whatever their vertex numbering.
fn faces_in(a: &PolyMesh, b: &PolyMesh) -> BTreeSet<Vec<usize>> {
    let map: Vec<usize> = a
        .positions
        .iter()
        .map(|&p| {
            let (i, d) = nearest(&b.positions, p);
            assert!(d < 1e-5, "no vertex near {p}");
            i
        })
        .collect();
    a.faces()
        .map(|f| {
            let mut k: Vec<usize> = f.iter().map(|&v| map[v as usize]).collect();
            let m = (0..k.len()).min_by_key(|&i| k[i]).unwrap();
            k.rotate_left(m);
            k
        })
        .collect()
}

fn same_faces(a: &PolyMesh, b: &PolyMesh) -> bool {
    faces_in(a, b) == faces_in(b, b)
}

fn nearest(positions: &[DVec3], p: DVec3) -> (usize, f64) {
    positions
        .iter()
        .enumerate()
        .map(|(i, q)| (i, (*q - p).length()))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap()
}

/// Oracle: the course's own before/after files. The edge each one operated on is recovered
/// from the difference, prism performs the same operation on it, and the oriented face sets
/// must then be equal (positions matched to 1e-6).
#[test]
fn flip_split_collapse_reproduce_the_course_examples() {
    for model in ["cube", "icosahedron", "torus"] {
        let input = load(&format!("meshedit/dae/{model}/input.dae"));
        let base = HalfedgeMesh::from_polymesh(&input).unwrap();
        let (v, e, f) = (base.vertex_count(), base.edge_count(), base.face_count());

        // Flip: the two faces that changed share the flipped edge.
        let after = load(&format!("meshedit/dae/{model}/edgeFlip.dae"));
        let now = faces_in(&after, &input);
        let gone: Vec<Vec<usize>> = faces_in(&input, &input).difference(&now).cloned().collect();
        assert_eq!(gone.len(), 2, "{model}: flip changed {} faces", gone.len());
        let shared: Vec<u32> = gone[0]
            .iter()
            .filter(|x| gone[1].contains(x))
            .map(|&x| x as u32)
            .collect();
        let mut h = base.clone();
        let edge = h
            .find_edge(VertexId(shared[0]), VertexId(shared[1]))
            .unwrap();
        h.flip(edge).unwrap();
        h.validate().unwrap();
        assert_eq!(
            (h.vertex_count(), h.edge_count(), h.face_count()),
            (v, e, f)
        );
        assert!(same_faces(&h.to_polymesh(), &after), "{model}: flip");

        // Split: the new vertex is the midpoint of the split edge.
        let after = load(&format!("meshedit/dae/{model}/edgeSplit.dae"));
        let added: Vec<DVec3> = after
            .positions
            .iter()
            .copied()
            .filter(|&p| nearest(&input.positions, p).1 > 1e-6)
            .collect();
        assert_eq!(added.len(), 1, "{model}: split");
        let mut h = base.clone();
        let edge = (0..h.edge_count() as u32)
            .map(prism_mesh::EdgeId)
            .find(|&e| {
                let he = h.edge_halfedge(e);
                let mid = (h.position(h.origin(he)) + h.position(h.dest(he))) / 2.0;
                (mid - added[0]).length() < 1e-6
            })
            .unwrap();
        h.split(edge).unwrap();
        h.validate().unwrap();
        assert_eq!(
            (h.vertex_count(), h.edge_count(), h.face_count()),
            (v + 1, e + 3, f + 2)
        );
        assert!(same_faces(&h.to_polymesh(), &after), "{model}: split");

        // Collapse: the two vertices that vanished are the collapsed edge's ends.
        let after = load(&format!("meshedit/dae/{model}/edgeCollapse.dae"));
        let vanished: Vec<u32> = (0..input.vertex_count() as u32)
            .filter(|&i| nearest(&after.positions, input.positions[i as usize]).1 > 1e-6)
            .collect();
        assert_eq!(vanished.len(), 2, "{model}: collapse");
        let mut h = base.clone();
        let edge = h
            .find_edge(VertexId(vanished[0]), VertexId(vanished[1]))
            .unwrap();
        h.collapse(edge).unwrap();
        h.validate().unwrap();
        assert_eq!(
            (h.vertex_count(), h.edge_count(), h.face_count()),
            (v - 1, e - 3, f - 2)
        );
        assert!(same_faces(&h.to_polymesh(), &after), "{model}: collapse");
    }
    // The counts FORMATS.md records for the cube.
    let cube = HalfedgeMesh::from_polymesh(&load("meshedit/dae/cube/input.dae")).unwrap();
    assert_eq!(
        (cube.vertex_count(), cube.face_count(), cube.edge_count()),
        (8, 12, 18)
    );
}

/// Oracle: libigl's `per_vertex_normals` (area-weighted) on the same triangles, committed as
/// `tests/golden/libigl/NAME.txt` (the bar is 1e-6; the two agree to about 1e-13).
fn normals_match_libigl(name: &str) {
    let mesh = load(&format!("meshedit/dae/{name}.dae"));
    let mine = prism_mesh::vertex_normals_area_weighted(&mesh);
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("tests/golden/libigl/{name}.txt"));
    let theirs: Vec<DVec3> = std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|t| t.parse().unwrap()).collect();
            DVec3::new(v[0], v[1], v[2])
        })
        .collect();
    assert_eq!(mine.len(), theirs.len(), "{name}");
    let worst = mine
        .iter()
        .zip(&theirs)
        .map(|(a, b)| (*a - *b).abs().max_element())
        .fold(0.0, f64::max);
    assert!(worst < 1e-9, "{name}: max difference {worst:e}");
}

#[test]
fn teapot_normals_match_libigl() {
    normals_match_libigl("teapot");
}

#[test]
fn beetle_normals_match_libigl() {
    normals_match_libigl("beetle");
}

fn scene(name: &str) -> prism_scene::Scene {
    let path = shared_assets().join(format!("pathtracer/dae/{name}"));
    let doc = read_collada(&path).unwrap();
    prism_scene::Scene::from_collada(&doc, &prism_scene::SceneOptions::default(), name).unwrap()
}

fn close(a: prism_math::Vec3, b: [f32; 3]) -> bool {
    (a - prism_math::Vec3::from_array(b)).length() < 2e-3
}

/// Oracle: the worked example of `FORMATS.md` section 2 (box, spheres, area light and the
/// course's camera placement for CBspheres_lambertian; CBbunny's mirrored camera).
#[test]
fn cornell_scenes_match_the_recorded_layout() {
    use prism_scene::{Light, Material};
    let s = scene("sky/CBspheres_lambertian.dae");
    let (lo, hi) = s.bounds().unwrap();
    assert!(
        close(lo, [-1.0, 0.0, -1.0]) && close(hi, [1.0, 1.5, 1.0]),
        "{lo} {hi}"
    );
    assert!(close(s.camera.eye, [0.0, 0.75, 4.8023]), "{:?}", s.camera);
    assert!(close(s.camera.target, [0.0, 0.75, 0.0]));
    let mut centres: Vec<[f32; 3]> = s.spheres.iter().map(|x| x.center.to_array()).collect();
    centres.sort_by(|a, b| a[0].total_cmp(&b[0]));
    assert!(close(
        prism_math::Vec3::from_array(centres[0]),
        [-0.4, 0.3, -0.3]
    ));
    assert!(close(
        prism_math::Vec3::from_array(centres[1]),
        [0.4, 0.3, 0.3]
    ));
    assert!(s.spheres.iter().all(|x| (x.radius - 0.3).abs() < 1e-5));
    assert_eq!(s.lights.len(), 1);
    let Light::Parallelogram {
        corner,
        edges: [dim_x, dim_y],
        colors,
        facing: Some(normal),
    } = &s.lights[0]
    else {
        panic!("expected an area light: {:?}", s.lights)
    };
    let center = *corner + 0.5 * *dim_x + 0.5 * *dim_y;
    assert!(close(center, [0.0, 1.49, 0.0]) && close(*normal, [0.0, -1.0, 0.0]));
    assert!((dim_x.cross(*dim_y).length() - 0.48).abs() < 1e-4);
    assert!(colors.iter().all(|c| c.to_array() == [10.0, 10.0, 10.0]));
    let (h, v) = s.camera.fov_for(512, 384);
    assert!(
        (h - 49.134).abs() < 1e-2 && (v - 37.849).abs() < 1e-2,
        "{h} {v}"
    );

    let b = scene("sky/CBbunny.dae");
    assert!(close(b.camera.eye, [0.0, 0.75, -4.8023]), "{:?}", b.camera);
    assert!(matches!(
        scene("sky/CBempty.dae").lights[..],
        [Light::Point { .. }]
    ));
    assert!(matches!(
        scene("sky/bunny.dae").lights[..],
        [Light::Hemisphere { .. }]
    ));
    let m = scene("sky/CBspheres_microfacet_al_ag.dae");
    assert!(m
        .materials
        .iter()
        .any(|x| matches!(x, Material::Microfacet { alpha, .. } if (*alpha - 0.25).abs() < 1e-6)));
    let g = scene("sky/CBspheres.dae");
    assert!(g
        .materials
        .iter()
        .any(|x| matches!(x, Material::Glass { ior, .. } if (*ior - 1.45).abs() < 1e-6)));
    assert!(g
        .materials
        .iter()
        .any(|x| matches!(x, Material::Mirror { .. })));
}

/// Every staged path-tracer file becomes a scene with geometry, a light and a camera.
#[test]
fn every_pathtracer_file_becomes_a_scene() {
    let mut files = Vec::new();
    dae_files(&shared_assets().join("pathtracer/dae"), &mut files);
    for f in files {
        let doc = read_collada(&f).unwrap();
        let s = prism_scene::Scene::from_collada(&doc, &prism_scene::SceneOptions::default(), "x")
            .unwrap();
        assert!(!s.meshes.is_empty(), "{}", f.display());
        assert!(s.camera.eye.is_finite());
        let name = f.file_name().unwrap().to_string_lossy().to_string();
        if name.starts_with("CB") || name.starts_with("bunny") {
            assert!(!s.lights.is_empty(), "{name}");
        }
        for m in &s.meshes {
            if let prism_scene::Shading::Smooth(n) = &m.shading {
                assert!(n
                    .iter()
                    .all(|v| (v.length() - 1.0).abs() < 1e-4 || *v == prism_math::Vec3::ZERO));
            }
        }
    }
}

/// Oracle: the built-in Cornell box is the staged CBspheres_lambertian (same box, spheres,
/// light and camera; materials equal up to the file's duplicated sphere material).
#[test]
fn built_in_cornell_box_matches_the_staged_file() {
    let file = scene("sky/CBspheres_lambertian.dae");
    let ours = prism_scene::cornell_box();
    let (a, b) = (file.bounds().unwrap(), ours.bounds().unwrap());
    assert!((a.0 - b.0).length() < 1e-5 && (a.1 - b.1).length() < 1e-5);
    assert_eq!(file.lights, ours.lights);
    assert!((file.camera.eye - ours.camera.eye).length() < 1e-5);
    assert!((file.camera.vfov - ours.camera.vfov).abs() < 1e-3);
    for (f, o) in file.spheres.iter().zip(&ours.spheres) {
        assert!((f.center - o.center).length() < 1e-6 && f.radius == o.radius);
        assert_eq!(file.materials[f.material], ours.materials[o.material]);
    }
    for (f, o) in file.meshes.iter().zip(&ours.meshes) {
        assert_eq!(f.name, o.name);
        assert_eq!(file.materials[f.material], ours.materials[o.material]);
        for (p, q) in f.positions.iter().zip(&o.positions) {
            assert!((*p - *q).length() < 1e-5, "{}: {p} {q}", f.name);
        }
    }
}

/// Real course files with the harmless defect some distributed copies have: the camera
/// node's `<matrix>` lacks its final number. Oracle: the intact file. The course's
/// placement reads the numbers in order, so the scene (camera included) is the intact one,
/// with a warning naming the line; the file's own camera (`CameraMode::File`) refuses it.
#[test]
fn course_files_with_a_short_camera_matrix_load_as_the_intact_ones() {
    for name in ["sky/CBspheres_lambertian.dae", "sky/CBbunny.dae"] {
        let path = shared_assets().join(format!("pathtracer/dae/{name}"));
        let text = std::fs::read_to_string(&path).expect("staged scene");
        let start = text.find("<node id=\"Camera\"").expect("a camera node");
        let open = start + text[start..].find("<matrix").unwrap();
        let close = open + text[open..].find("</matrix>").unwrap();
        let matrix = &text[open..close];
        let short = format!(
            "{}{}",
            &text[..open],
            &text[open..].replacen(matrix, matrix.trim_end_matches(" 1"), 1)
        );
        assert_ne!(short, text, "{name}: the matrix did not end in 1");
        let options = prism_scene::SceneOptions::default();
        let doc = prism_scene::parse_collada(&short, name).unwrap();
        let line = 1 + text[..open].matches('\n').count();
        assert!(
            doc.warnings[0]
                .to_string()
                .starts_with(&format!("{name}:{line}: <matrix>: expected 16 numbers")),
            "{:?}",
            doc.warnings
        );
        let got = prism_scene::Scene::from_collada(&doc, &options, name).unwrap();
        assert_eq!(got.camera, scene(name).camera, "{name}");
        assert_eq!(got.lights, scene(name).lights, "{name}");
        let file_camera = prism_scene::SceneOptions {
            camera: prism_scene::CameraMode::File,
            ..options
        };
        assert!(prism_scene::Scene::from_collada(&doc, &file_camera, name).is_err());
    }
}

/// Property over the course's files: every MeshEdit file (`meshedit/dae`, and the copies of
/// its meshes in `pathtracer/dae/meshedit`) is lit only by a default lamp, so `prism view`
/// opens it to edit; every path-tracer scene with its own light is not.
#[test]
fn meshedit_files_and_only_they_are_lit_by_a_default_lamp() {
    let mut files = Vec::new();
    for d in ["meshedit/dae", "pathtracer/dae"] {
        dae_files(&shared_assets().join(d), &mut files);
    }
    files.sort();
    let mut lamp_lit = Vec::new();
    for f in &files {
        let scene = prism_scene::load(f, &prism_scene::SceneOptions::default())
            .unwrap_or_else(|e| panic!("{e}"));
        let rel = f
            .strip_prefix(shared_assets())
            .unwrap()
            .display()
            .to_string();
        let meshedit = rel.contains("meshedit/");
        if scene.lit_only_by_a_default_lamp() {
            lamp_lit.push(rel.clone());
        }
        assert_eq!(
            scene.lit_only_by_a_default_lamp(),
            meshedit || !scene.is_lit(),
            "{rel}"
        );
    }
    assert!(lamp_lit.len() >= 10, "{lamp_lit:?}");
}
