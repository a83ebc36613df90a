//! Tests of the OBJ scene reader against hand-computed values.

use super::*;

fn no_files(name: &str) -> Result<Vec<u8>, SceneError> {
    Err(SceneError::NotAFile {
        path: name.to_string(),
    })
}

fn lib(mtl: &'static str) -> impl Fn(&str) -> Result<Vec<u8>, SceneError> {
    move |name: &str| {
        if name == "m.mtl" {
            Ok(mtl.as_bytes().to_vec())
        } else {
            no_files(name)
        }
    }
}

/// Closed form: a quad is a fan of two triangles; with `vn` the file's normal is kept, with
/// `vt` the file's uv; corners equal in (position, normal, uv) are one vertex.
#[test]
fn quad_fans_and_shares_vertices() {
    let s = parse_obj_scene(
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 2\n\
         f 1/1/1 2/2/1 3/3/1 4/4/1\n",
        "q.obj",
        &no_files,
        false,
    )
    .unwrap();
    assert_eq!(s.meshes.len(), 1);
    let m = &s.meshes[0];
    assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    assert_eq!(m.positions.len(), 4);
    assert_eq!(
        m.shading,
        Shading::Smooth(vec![Vec3::new(0.0, 0.0, 2.0); 4])
    );
    assert_eq!(m.uvs.as_ref().unwrap()[2], Vec2::new(1.0, 1.0));
    // No material: kd 1, ks 0, Ns 1.
    assert_eq!(
        s.materials[0],
        Material::Phong {
            kd: Rgb::WHITE,
            ks: Rgb::BLACK,
            shininess: 1.0,
            kd_texture: None,
            transparency: 1.0
        }
    );
}

/// Property: without `vn` a corner takes its triangle's geometric normal, so two
/// triangles sharing positions but not planes do not share vertices; without any `vt` in
/// the file a `v/vt` corner reads (0, 0) (the staged triangle.obj).
#[test]
fn missing_normals_and_uvs() {
    let s = parse_obj_scene(
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1/1 2/1 3/1\nf 1 3 4\n",
        "t.obj",
        &no_files,
        false,
    )
    .unwrap();
    let m = &s.meshes[0];
    assert_eq!(m.positions.len(), 6);
    let Shading::Smooth(n) = &m.shading else {
        panic!()
    };
    assert_eq!(n[0], Vec3::Z);
    assert_eq!(n[3], Vec3::X);
    assert!(m.uvs.as_ref().unwrap().iter().all(|&uv| uv == Vec2::ZERO));
}

/// A material change starts a sub-mesh; a material used twice is one material.
#[test]
fn runs_split_by_material() {
    let mtl = "newmtl a\nKd 1 0 0\nnewmtl b\nKd 0 1 0\nKs 0.5 0.5 0.5\nNs 8\nd 0.25\n";
    let s = parse_obj_scene(
        "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\nusemtl b\nf 1 2 3\n\
         usemtl a\nf 1 2 3\nf 1 3 2\n",
        "r.obj",
        &lib(mtl),
        false,
    )
    .unwrap();
    assert_eq!(s.meshes.len(), 3);
    assert_eq!(
        s.meshes.iter().map(|m| m.material).collect::<Vec<_>>(),
        [0, 1, 0]
    );
    assert_eq!(s.meshes[2].triangles.len(), 2);
    assert_eq!(s.material_names, ["a", "b"]);
    assert_eq!(
        s.materials[1],
        Material::Phong {
            kd: Rgb::new(0.0, 1.0, 0.0),
            ks: Rgb::splat(0.5),
            shininess: 8.0,
            kd_texture: None,
            transparency: 0.25
        }
    );
}

/// Closed form: normalisation moves the vertices' mean to the origin and the farthest
/// vertex to distance 1.
#[test]
fn normalisation_is_mean_and_max_distance() {
    let s = parse_obj_scene(
        "v 2 0 0\nv 4 0 0\nv 2 2 0\nf 1 2 3\n",
        "n.obj",
        &no_files,
        true,
    )
    .unwrap();
    let p = &s.meshes[0].positions;
    let mean = p.iter().fold(Vec3::ZERO, |a, &q| a + q) / 3.0;
    assert!(mean.length() < 1e-6, "{mean}");
    let far = p.iter().map(|q| q.length()).fold(0.0f32, f32::max);
    assert!((far - 1.0).abs() < 1e-6, "{far}");
}

/// Malformed input is a located error, never a panic.
#[test]
fn malformed_input_is_located() {
    let cases: [(&str, &str); 8] = [
        ("v 0 0\n", "t.obj:1: v: expected 3 numbers, found 2"),
        (
            "v 0 nan 0\n",
            "t.obj:1: v: expected a finite number, found \"nan\"",
        ),
        (
            "v 0 0 0\nf 1 2 3\n",
            "t.obj:2: f: vertex index 2 is out of range (1 defined so far)",
        ),
        (
            "v 0 0 0\nf 1 1\n",
            "t.obj:2: f: expected at least 3 corners, found 2",
        ),
        (
            "v 0 0 0\nvt 0 0\nf 1/2 1/1 1/1\n",
            "t.obj:3: f: texture coordinate index 2 is out of range (1 defined so far)",
        ),
        (
            "usemtl x\n",
            "t.obj:1: usemtl x: no material library was named before it",
        ),
        (
            "mtllib m.mtl\nusemtl x\n",
            "t.obj:2: usemtl x: no such material in m.mtl",
        ),
        (
            "v 0 0 0\nvt 0 0\nf 1/x 1 1\n",
            "t.obj:3: f: expected a texture coordinate index, found \"1/x\"",
        ),
    ];
    for (text, want) in cases {
        let e = parse_obj_scene(text, "t.obj", &lib("newmtl a\n"), false).unwrap_err();
        assert_eq!(e.to_string(), want, "{text:?}");
    }
    let e = parse_obj_scene("mtllib gone.mtl\n", "t.obj", &no_files, false).unwrap_err();
    assert!(
        e.to_string().starts_with("t.obj:1: mtllib: cannot read"),
        "{e}"
    );
    let e = parse_obj_scene(
        "mtllib m.mtl\nusemtl a\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
        "t.obj",
        &lib("newmtl a\nmap_Kd gone.png\n"),
        false,
    )
    .unwrap_err();
    assert!(
        e.to_string()
            .starts_with("m.mtl:2: material a: map_Kd gone.png: cannot read"),
        "{e}"
    );
}

/// Fan-out: a library named 10,000 times on one line and again on another, spelled four
/// ways, is read once; a texture two materials share (spelled two ways) is read and
/// decoded once, and both hold the same image;
/// `usemtl` finds the last definition of a name (as a search from the end would).
#[test]
fn libraries_and_textures_are_read_once() {
    let reads = std::cell::RefCell::new(Vec::new());
    let png = prism_image::encode_png(&prism_image::Image::new(2, 2, [200, 10, 10])).unwrap();
    let files = |name: &str| -> Result<Vec<u8>, SceneError> {
        reads.borrow_mut().push(name.to_string());
        match name {
            "m.mtl" => Ok(b"newmtl a\nKd 1 0 0\nnewmtl b\nmap_Kd t.png\n\
                            newmtl a\nKd 0 0 1\nmap_Kd ./t.png\n"
                .to_vec()),
            "t.png" | "./t.png" => Ok(png.clone()),
            _ => no_files(name),
        }
    };
    let obj = format!(
        "mtllib {}\nmtllib m.mtl ./m.mtl sub/../m.mtl .//m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n\
         vt 0 0\nusemtl a\nf 1 2 3\nusemtl b\nf 1 2 3\nusemtl a\nf 3 2 1\n",
        ["m.mtl"; 10_000].join(" ")
    );
    let s = parse_obj_scene(&obj, "fan.obj", &files, false).unwrap();
    assert_eq!(*reads.borrow(), ["m.mtl", "./t.png"]);
    assert_eq!(s.material_names, ["a", "b"]);
    let texture = |m: &Material| match m {
        Material::Phong {
            kd,
            kd_texture: Some(t),
            ..
        } => (*kd, Arc::clone(&t.image)),
        m => panic!("{m:?}"),
    };
    let (kd, a) = texture(&s.materials[0]);
    assert_eq!(kd, Rgb::new(0.0, 0.0, 1.0), "the last `a` wins");
    let (_, b) = texture(&s.materials[1]);
    assert!(Arc::ptr_eq(&a, &b), "one decoded image");
}

/// Lookup by name is a hash: 100,000 materials, each used once, parse in well under the
/// time a search per `usemtl` would take (about 5 * 10^9 comparisons).
#[test]
fn many_materials_are_looked_up_by_hash() {
    let n = 100_000;
    let mut mtl = String::new();
    let mut obj = String::from("mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n");
    for i in 0..n {
        mtl.push_str(&format!("newmtl m{i}\nKd 0.5 0.5 0.5\n"));
        obj.push_str(&format!("usemtl m{}\nf 1 2 3\n", n - 1 - i));
    }
    let mtl: &'static str = Box::leak(mtl.into_boxed_str());
    let s = parse_obj_scene(&obj, "many.obj", &lib(mtl), false).unwrap();
    assert_eq!(s.materials.len(), n);
    assert_eq!(s.material_names[0], format!("m{}", n - 1));
}

/// A corner naming a texture coordinate or normal that is not a number is an error even
/// in a file without any `vt` or `vn` (where a number there reads as none).
#[test]
fn corners_name_numbers_even_without_uvs() {
    let ok = parse_obj_scene(
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1 2/2 3/3\n",
        "ok.obj",
        &no_files,
        false,
    );
    assert!(ok.is_ok());
    for (face, what) in [
        ("f 1/a 2 3", "texture coordinate"),
        ("f 1//x 2 3", "normal"),
        ("f 1/0 2 3", "texture coordinate"),
    ] {
        let text = format!("v 0 0 0\nv 1 0 0\nv 0 1 0\n{face}\n");
        let e = parse_obj_scene(&text, "bad.obj", &no_files, false)
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            format!(
                "bad.obj:4: f: expected a {what} index, found {:?}",
                &face[2..face
                    .find(' ')
                    .map_or(face.len(), |_| face[2..].find(' ').unwrap() + 2)]
            ),
            "{face}"
        );
    }
}
