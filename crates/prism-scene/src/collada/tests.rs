//! Tests of the COLLADA reader and writer: primitives, transforms, up axes, CGL extras,
//! located errors and limits, warnings, and the writer's round trip.

use prism_math::glam::{DVec2, DVec3};
use prism_mesh::PolyMesh;

use super::*;

fn doc(up: &str, geometry: &str, nodes: &str) -> String {
    format!(
        r##"<?xml version="1.0"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><up_axis>{up}</up_axis></asset>
  <library_cameras><camera id="cam"><optics><technique_common><perspective><xfov>40</xfov>
    <aspect_ratio>1.5</aspect_ratio></perspective></technique_common></optics></camera></library_cameras>
  <library_lights><light id="sun"><technique_common><directional><color>1 1 1</color></directional>
    </technique_common></light></library_lights>
  <library_effects><effect id="red-fx"><profile_COMMON><technique sid="common"><phong><diffuse>
    <color>0.8 0.1 0.1 1</color></diffuse></phong></technique></profile_COMMON></effect></library_effects>
  <library_materials><material id="red"><instance_effect url="#red-fx"/></material></library_materials>
  <library_geometries>{geometry}</library_geometries>
  <library_visual_scenes><visual_scene id="s">{nodes}</visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#s"/></scene>
</COLLADA>"##
    )
}

/// Two triangles sharing an edge: a unit square in z = 0, normals and uvs indexed apart.
const SQUARE: &str = r##"<geometry id="sq" name="Square"><mesh>
  <source id="p"><float_array id="pa" count="12">0 0 0 1 0 0 1 1 0 0 1 0</float_array>
    <technique_common><accessor source="#pa" count="4" stride="3"/></technique_common></source>
  <source id="n"><float_array id="na" count="3">0 0 1</float_array>
    <technique_common><accessor source="#na" count="1" stride="3"/></technique_common></source>
  <source id="t"><float_array id="ta" count="8">0 0 1 0 1 1 0 1</float_array>
    <technique_common><accessor source="#ta" count="4" stride="2"/></technique_common></source>
  <vertices id="v"><input semantic="POSITION" source="#p"/></vertices>
  <polylist material="paint" count="2">
    <input semantic="VERTEX" source="#v" offset="0"/>
    <input semantic="NORMAL" source="#n" offset="1"/>
    <input semantic="TEXCOORD" source="#t" offset="2" set="0"/>
    <vcount>3 3</vcount>
    <p>0 0 0 1 0 1 2 0 2  0 0 0 2 0 2 3 0 3</p>
  </polylist>
</mesh></geometry>"##;

fn node(transforms: &str) -> String {
    format!(
        r##"<node id="n" name="N">{transforms}<instance_geometry url="#sq"><bind_material><technique_common>
        <instance_material symbol="paint" target="#red"/></technique_common></bind_material></instance_geometry></node>"##
    )
}

fn assert_close(a: DVec3, b: DVec3) {
    assert!((a - b).length() < 1e-12, "{a} != {b}");
}

#[test]
fn polylist_reads_shared_positions_and_per_corner_attributes() {
    let c = parse_collada(&doc("Y_UP", SQUARE, &node("")), "t.dae").unwrap();
    let Shape::Mesh(m) = &c.geometries[0].shape else {
        panic!("expected a mesh")
    };
    assert_eq!(m.mesh.vertex_count(), 4);
    assert_eq!(m.mesh.face(0), &[0, 1, 2]);
    assert_eq!(m.mesh.face(1), &[0, 2, 3]);
    assert_eq!(m.corner_normals.as_ref().unwrap().len(), 6);
    // Every corner of a vertex agrees, so the attributes are per-vertex too.
    assert_eq!(m.mesh.normals.as_ref().unwrap()[2], DVec3::Z);
    assert_eq!(m.mesh.uvs.as_ref().unwrap()[2], DVec2::new(1.0, 1.0));
    assert_eq!(
        m.parts,
        vec![Part {
            material: Some("paint".into()),
            faces: 0..2
        }]
    );
    assert_eq!(
        c.nodes[0].instances,
        vec![Instance::Geometry {
            geometry: 0,
            materials: vec![("paint".into(), "red".into())],
            defect: None,
        }]
    );
}

#[test]
fn triangles_and_polygons_read_like_polylist() {
    let tri = SQUARE
        .replace("<polylist", "<triangles")
        .replace("</polylist>", "</triangles>")
        .replace("<vcount>3 3</vcount>", "");
    let c = parse_collada(&doc("Y_UP", &tri, &node("")), "t.dae").unwrap();
    let poly = SQUARE
        .replace("<polylist", "<polygons")
        .replace("</polylist>", "</polygons>")
        .replace("<vcount>3 3</vcount>", "")
        .replace(
            "<p>0 0 0 1 0 1 2 0 2  0 0 0 2 0 2 3 0 3</p>",
            "<p>0 0 0 1 0 1 2 0 2 3 0 3</p>",
        );
    let q = parse_collada(&doc("Y_UP", &poly, &node("")), "t.dae").unwrap();
    let (Shape::Mesh(a), Shape::Mesh(b)) = (&c.geometries[0].shape, &q.geometries[0].shape) else {
        panic!("expected meshes")
    };
    assert_eq!(a.mesh.face_count(), 2);
    assert_eq!(b.mesh.face(0), &[0, 1, 2, 3]);
}

/// Oracle: the transforms written out by hand (rotation about X by -5 degrees, then
/// translation), which is COLLADA's document-order product `T·R_Y·R_X·R_Z`.
#[test]
fn translate_then_rotate_composes_in_document_order() {
    let t = r#"<translate>0 0.75 4</translate><rotate>0 1 0 0</rotate><rotate>1 0 0 -5</rotate><rotate>0 0 1 0</rotate>"#;
    let c = parse_collada(&doc("Y_UP", SQUARE, &node(t)), "t.dae").unwrap();
    let w = c.nodes[0].world;
    let a = (-5.0f64).to_radians();
    // The point (0, 1, 0) rotated about X by a is (0, cos a, sin a).
    let expect = DVec3::new(0.0, a.cos(), a.sin()) + DVec3::new(0.0, 0.75, 4.0);
    assert_close(w.transform_point3(DVec3::Y), expect);
    assert_close(w.transform_point3(DVec3::ZERO), DVec3::new(0.0, 0.75, 4.0));
}

/// Oracle: COLLADA matrices are row-major, so translation sits in elements 3, 7 and 11.
#[test]
fn matrix_is_row_major() {
    let t = "<matrix>2 0 0 7 0 2 0 8 0 0 2 9 0 0 0 1</matrix>";
    let c = parse_collada(&doc("Y_UP", SQUARE, &node(t)), "t.dae").unwrap();
    assert_close(
        c.nodes[0].world.transform_point3(DVec3::ONE),
        DVec3::new(9.0, 10.0, 11.0),
    );
    let m = c.world_mesh(false).unwrap();
    assert_close(m.positions[2], DVec3::new(9.0, 10.0, 9.0));
}

#[test]
fn nested_nodes_compose_parent_first() {
    let inner = node("<scale>2 2 2</scale>");
    let outer = format!(r#"<node id="o"><translate>1 0 0</translate>{inner}</node>"#);
    let c = parse_collada(&doc("Y_UP", SQUARE, &outer), "t.dae").unwrap();
    assert_eq!(c.nodes.len(), 2);
    assert_close(
        c.nodes[1].world.transform_point3(DVec3::ONE),
        DVec3::new(3.0, 2.0, 2.0),
    );
}

/// Oracle: the course's Z-up conversion, (x, y, z) -> (-x, z, y) (FORMATS.md section 2).
#[test]
fn z_up_converts_to_y_up_like_the_course() {
    let t = "<translate>1 2 3</translate>";
    let c = parse_collada(&doc("Z_UP", SQUARE, &node(t)), "t.dae").unwrap();
    assert_eq!(c.up_axis, UpAxis::Z);
    let m = c.world_mesh(true).unwrap();
    assert_close(m.positions[0], DVec3::new(-1.0, 3.0, 2.0));
    // The +Z normal becomes +Y.
    assert_close(m.normals.as_ref().unwrap()[0], DVec3::Y);
    assert!((UpAxis::Z.to_y_up().determinant() - 1.0).abs() < 1e-15);
    assert!((UpAxis::X.to_y_up().determinant() - 1.0).abs() < 1e-15);
    assert_close(UpAxis::X.to_y_up().transform_point3(DVec3::X), DVec3::Y);
}

#[test]
fn cgl_sphere_geometry() {
    let g = r#"<geometry id="sq"><extra><technique profile="CGL"><sphere><radius>.3</radius></sphere></technique></extra></geometry>"#;
    let c = parse_collada(&doc("Z_UP", g, &node("")), "t.dae").unwrap();
    assert!(matches!(c.geometries[0].shape, Shape::Sphere { radius } if radius == 0.3));
    assert_eq!(c.world_mesh(true).unwrap().face_count(), 0);
}

#[test]
fn comments_are_skipped() {
    let nodes = format!(
        "<!--<node id=\"light\"><instance_geometry url=\"#nothing\"/></node>-->{}",
        node("")
    );
    let c = parse_collada(&doc("Y_UP", SQUARE, &nodes), "t.dae").unwrap();
    assert_eq!(c.nodes.len(), 1);
}

#[test]
fn unknown_primitives_warn_once() {
    let g = SQUARE.replace(
        "<polylist",
        "<lines count=\"1\"><input semantic=\"VERTEX\" source=\"#v\" offset=\"0\"/><p>0 1</p></lines>\
         <lines count=\"1\"><input semantic=\"VERTEX\" source=\"#v\" offset=\"0\"/><p>1 2</p></lines><polylist",
    );
    let c = parse_collada(&doc("Y_UP", &g, &node("")), "t.dae").unwrap();
    assert_eq!(c.warnings.len(), 1, "{:?}", c.warnings);
    assert!(c.warnings[0].to_string().contains("<lines>"));
}

/// The error a document gives its users: the reader, the world mesh or the scene.
fn error_of(text: &str) -> String {
    let used = parse_collada(text, "bad.dae").and_then(|c| {
        c.world_mesh(true)?;
        crate::Scene::from_collada(&c, &crate::SceneOptions::default(), "bad.dae")
    });
    used.unwrap_err().to_string()
}

#[test]
fn bad_input_gives_located_errors() {
    let cases: Vec<(String, &str)> = vec![
        (
            doc(
                "Y_UP",
                &SQUARE.replace("2 0 2 3 0 3", "2 0 2 9 0 3"),
                &node(""),
            ),
            "vertex index 9 is out of range",
        ),
        (
            doc(
                "Y_UP",
                &SQUARE.replace("0 0 0 1 0 0 1 1 0", "0 0 0 1 0 NaN 1 1 0"),
                &node(""),
            ),
            "expected a finite value",
        ),
        (
            doc(
                "Y_UP",
                &SQUARE.replace("count=\"12\"", "count=\"13\""),
                &node(""),
            ),
            "count says 13 numbers but 12 are given",
        ),
        (
            doc(
                "Y_UP",
                &SQUARE.replace("<vcount>3 3</vcount>", "<vcount>3 2</vcount>"),
                &node(""),
            ),
            "expected 15 indices",
        ),
        (
            doc("Y_UP", SQUARE, &node("").replace("#sq", "#nope")),
            "no <geometry> with id \"nope\"",
        ),
        (
            doc(
                "Y_UP",
                SQUARE,
                &node("<matrix>1 0 0 0 0 1 0 0 0 0 1 0 0 0 0</matrix>"),
            ),
            "expected 16 numbers, found 15",
        ),
        (
            doc(
                "Y_UP",
                SQUARE,
                &node("<matrix>1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 inf</matrix>"),
            ),
            "expected a finite value",
        ),
        (
            doc("Y_UP", SQUARE, &node("<rotate>0 0 0 30</rotate>")),
            "non-zero rotation axis",
        ),
        (
            doc("W_UP", SQUARE, &node("")),
            "expected X_UP, Y_UP or Z_UP",
        ),
        (
            doc(
                "Y_UP",
                SQUARE,
                r##"<node><instance_light url="#moon"/></node>"##,
            ),
            "no <light> with id \"moon\"",
        ),
        ("<COLLADA><asset>".to_string(), "bad.dae: "),
        ("<svg/>".to_string(), "expected a <COLLADA> root element"),
    ];
    for (text, want) in cases {
        let e = error_of(&text);
        assert!(e.contains(want), "{e:?} lacks {want:?}");
        assert!(e.starts_with("bad.dae"), "{e:?}");
    }
    // The line of the element is named.
    let e = error_of(&doc(
        "Y_UP",
        &SQUARE.replace("2 0 2 3 0 3", "2 0 2 9 0 3"),
        &node(""),
    ));
    assert!(e.starts_with("bad.dae:24: <p>:"), "{e}");
}

#[test]
fn self_instancing_nodes_are_refused() {
    let text = r##"<COLLADA><library_nodes><node id="a"><instance_node url="#a"/></node></library_nodes>
      <library_visual_scenes><visual_scene id="s"><node><instance_node url="#a"/></node></visual_scene></library_visual_scenes></COLLADA>"##;
    assert!(error_of(text).contains("instances a node that contains it"));
}

/// Oracle: the writer's output read back is the same mesh (property: lossless round trip).
#[test]
fn writer_round_trips() {
    let mut m = PolyMesh::new(
        vec![
            DVec3::new(0.1, 0.2, 0.3),
            DVec3::new(1.0 / 3.0, 0.0, 0.0),
            DVec3::new(1.0, 1e-300, 0.0),
            DVec3::new(0.0, 1.0, -7.5),
        ],
        &[vec![0, 1, 2], vec![0, 2, 3, 1]],
    );
    m.normals = Some(vec![DVec3::X, DVec3::Y, DVec3::Z, DVec3::NEG_X]);
    m.uvs = Some(vec![DVec2::ZERO, DVec2::X, DVec2::ONE, DVec2::Y]);
    let mut bytes = Vec::new();
    write_collada(&m, &mut bytes).unwrap();
    let c = parse_collada(std::str::from_utf8(&bytes).unwrap(), "rt.dae").unwrap();
    assert_eq!(c.world_mesh(true).unwrap(), m);
}

/// Unsupported features warn once each instead of vanishing silently.
#[test]
fn unsupported_features_warn() {
    let text = doc("Y_UP", SQUARE, &node(""))
        .replace(
            "<directional><color>1 1 1</color></directional>",
            "<spotlight><color>1 1 1</color></spotlight>",
        )
        .replace(
            "<color>0.8 0.1 0.1 1</color>",
            "<texture texture=\"img\" texcoord=\"uv\"/>",
        )
        .replace(
            "</effect>",
            "<extra><technique profile=\"CGL\"><velvet><x>1</x></velvet></technique></extra></effect>",
        );
    let c = parse_collada(&text, "w.dae").unwrap();
    let all = c
        .warnings
        .iter()
        .map(ToString::to_string)
        .collect::<Vec<_>>()
        .join("\n");
    for want in ["<spotlight>", "<velvet>"] {
        assert!(all.contains(want), "{want} not warned: {all}");
    }
}

/// The 1-based line where `needle` first occurs in `text`.
fn line_of(text: &str, needle: &str) -> u32 {
    let at = text.find(needle).expect("needle in text");
    1 + text[..at].matches('\n').count() as u32
}

/// Property: 100,000 nested `<node>` elements end in the located depth error, on a test
/// thread's small stack (the XML parse and the walk check the depth before going deeper).
#[test]
fn hundred_thousand_nested_nodes_are_a_located_error() {
    let levels = 100_000;
    let nodes = format!("{}{}", "<node>".repeat(levels), "</node>".repeat(levels));
    let text = doc("Y_UP", SQUARE, &format!("\n{nodes}"));
    let e = parse_collada(&text, "deep.dae").unwrap_err().to_string();
    let at = format!("deep.dae:{}: <node>:", line_of(&text, "<node><node>"));
    assert!(e.starts_with(&at), "{e}");
    assert!(
        e.contains(&format!("nest deeper than {MAX_NODE_DEPTH}")),
        "{e}"
    );
}

/// Closed form: `k` library nodes, each instancing the previous one twice, expand to
/// `2^k − 1` nodes below the top one. Past [`MAX_NODES`] the document is refused before
/// anything is expanded; below it every copy is there.
#[test]
fn instance_node_fan_out_is_counted_before_expanding() {
    let chain = |k: usize| {
        let mut lib = String::from("<library_nodes><node id='n0'/>");
        for i in 1..k {
            lib += &format!(
                "<node id='n{i}'><instance_node url='#n{p}'/><instance_node url='#n{p}'/></node>",
                p = i - 1
            );
        }
        lib += "</library_nodes>";
        format!(
            "<COLLADA>{lib}<library_visual_scenes><visual_scene id='s'><node>\
             <instance_node url='#n{}'/></node></visual_scene></library_visual_scenes></COLLADA>",
            k - 1
        )
    };
    let c = parse_collada(&chain(10), "fan.dae").unwrap();
    assert_eq!(c.nodes.len(), 1 + (1 << 10) - 1);
    let e = parse_collada(&chain(40), "fan.dae")
        .unwrap_err()
        .to_string();
    assert!(e.contains(&format!("more than {MAX_NODES} nodes")), "{e}");
}

/// The course's camera node with a 15-number matrix (the final 1 missing).
fn short_camera_matrix(text: &str) -> String {
    text.replace(
        "<node id=\"Camera\" name=\"Camera\" type=\"NODE\">",
        "<node id=\"Camera\" name=\"Camera\" type=\"NODE\">\n<matrix>1 0 0 0 0 0 1 3 0 -1 0 0 0 0 0</matrix>",
    )
}

fn camera_doc(camera_transform: &str) -> String {
    doc("Y_UP", SQUARE, &node("")).replace(
        "</visual_scene>",
        &format!(
            "<node id=\"Camera\" name=\"Camera\" type=\"NODE\">{camera_transform}\
             <instance_camera url=\"#cam\"/></node></visual_scene>"
        ),
    )
}

/// The rule: a malformed value nothing uses is a warning naming file, line and element; a
/// malformed value that is used is an error. Oracle for the camera: the course reads a
/// short matrix in order, so the camera it places is the intact file's.
#[test]
fn malformed_values_are_errors_only_where_used() {
    let intact = camera_doc("<matrix>1 0 0 0 0 0 1 3 0 -1 0 0 0 0 0 1</matrix>");
    let short = short_camera_matrix(&camera_doc(""));
    let course = crate::SceneOptions::default();
    let file_camera = crate::SceneOptions {
        camera: crate::CameraMode::File,
        ..Default::default()
    };
    let c = parse_collada(&short, "cam.dae").unwrap();
    let at = format!(
        "cam.dae:{}: <matrix>:",
        line_of(&short, "<matrix>1 0 0 0 0 0 1 3")
    );
    assert!(
        c.warnings[0]
            .to_string()
            .starts_with(&format!("{at} expected 16 numbers, found 15")),
        "{:?}",
        c.warnings
    );
    // Meshes do not use the camera; the course's placement reads the numbers in order.
    assert!(c.world_mesh(true).is_ok());
    let scene = crate::Scene::from_collada(&c, &course, "cam.dae").unwrap();
    let reference = crate::Scene::from_collada(
        &parse_collada(&intact, "cam.dae").unwrap(),
        &course,
        "cam.dae",
    )
    .unwrap();
    assert_eq!(scene.camera, reference.camera);
    assert!(scene
        .warnings
        .iter()
        .any(|w| w.to_string().contains("camera node")));
    // The file's own camera uses the matrix: an error.
    let e = crate::Scene::from_collada(&c, &file_camera, "cam.dae").unwrap_err();
    assert!(e.to_string().starts_with(&at), "{e}");

    // A malformed effect, light or geometry nobody instances is a warning.
    let unused = doc("Y_UP", SQUARE, &node(""))
        .replace(
            "</library_effects>",
            "<effect id=\"bad-fx\"><extra><technique profile=\"CGL\"><mirror><reflectance>1 x 1\
             </reflectance></mirror></technique></extra></effect></library_effects>",
        )
        .replace(
            "</library_lights>",
            "<light id=\"bad\"><technique_common><point><color>1</color></point>\
             </technique_common></light></library_lights>",
        )
        .replace(
            "</library_geometries>",
            "<geometry id=\"broken\"><mesh><vertices id=\"v\"/></mesh></geometry></library_geometries>",
        );
    let c = parse_collada(&unused, "u.dae").unwrap();
    assert_eq!(c.warnings.len(), 3, "{:?}", c.warnings);
    assert!(c.world_mesh(true).is_ok());
    assert!(crate::Scene::from_collada(&c, &course, "u.dae").is_ok());
    // Used, each is an error; the mesh commands still read what they use.
    let lit = unused.replace(
        "</visual_scene>",
        "<node><instance_light url=\"#bad\"/></node></visual_scene>",
    );
    let c = parse_collada(&lit, "u.dae").unwrap();
    assert!(c.world_mesh(true).is_ok());
    let e = crate::Scene::from_collada(&c, &course, "u.dae").unwrap_err();
    assert!(
        e.to_string().contains("<color>: expected 3 colour values"),
        "{e}"
    );
    let placed = unused.replace("url=\"#sq\"", "url=\"#broken\"");
    let e = error_of(&placed.replace("u.dae", "bad.dae"));
    assert!(e.contains("<vertices>: expected a POSITION input"), "{e}");
    let bound = unused.replace(
        "<instance_effect url=\"#red-fx\"/>",
        "<instance_effect url=\"#bad-fx\"/>",
    );
    let e = error_of(&bound);
    assert!(e.contains("<reflectance>: number 1"), "{e}");
}

/// A light or camera instance with no target is refused by the renderer, which reads them,
/// and not by the mesh commands, which do not.
#[test]
fn missing_instance_targets_fail_only_their_users() {
    let text = doc("Y_UP", SQUARE, &node("")).replace(
        "</visual_scene>",
        "<node><instance_light url=\"#moon\"/></node></visual_scene>",
    );
    let c = parse_collada(&text, "m.dae").unwrap();
    assert!(c.world_mesh(true).is_ok());
    let e = crate::Scene::from_collada(&c, &crate::SceneOptions::default(), "m.dae").unwrap_err();
    assert!(e.to_string().contains("no <light> with id \"moon\""), "{e}");
}

/// A common-profile diffuse `<texture>` names its image through the effect's sampler and
/// surface parameters (COLLADA 1.4.1), or names an image id directly; an image id that
/// is not in `<library_images>` is a located error once the effect is used.
#[test]
fn diffuse_textures_resolve_to_image_files() {
    let images = r#"<library_images><image id="checker-img"><init_from>tex/checker.png</init_from></image>
      <image id="other"><init_from>file://other.jpg</init_from></image></library_images>"#;
    let chain = r#"<profile_COMMON><newparam sid="surf"><surface type="2D"><init_from>checker-img</init_from></surface></newparam>
      <newparam sid="samp"><sampler2D><source>surf</source></sampler2D></newparam>
      <technique sid="common"><phong><diffuse><texture texture="samp" texcoord="UVMap"/></diffuse></phong></technique></profile_COMMON>"#;
    let base = doc("Y_UP", SQUARE, &node(""));
    let with = |effect_body: &str| {
        let start = base.find("<profile_COMMON>").unwrap();
        let end = base.find("</profile_COMMON>").unwrap() + "</profile_COMMON>".len();
        format!("{}{}{}", &base[..start], effect_body, &base[end..])
            .replace("<library_effects>", &format!("{images}<library_effects>"))
    };
    let text = with(chain);
    let c = parse_collada(&text, "t.dae").unwrap();
    let line = line_of(&text, "<texture texture=");
    assert_eq!(
        c.effects[0].diffuse_texture,
        Some(("tex/checker.png".to_string(), line))
    );
    let direct = with(
        r#"<profile_COMMON><technique sid="common"><phong><diffuse><texture texture="other" texcoord="UVMap"/></diffuse></phong></technique></profile_COMMON>"#,
    );
    let c = parse_collada(&direct, "t.dae").unwrap();
    assert_eq!(
        c.effects[0].diffuse_texture.as_ref().unwrap().0,
        "other.jpg"
    );
    let missing = text.replace(
        "<init_from>checker-img</init_from>",
        "<init_from>nothing</init_from>",
    );
    let c = parse_collada(&missing, "t.dae").unwrap();
    let e = crate::Scene::from_collada(&c, &crate::SceneOptions::default(), "t.dae").unwrap_err();
    assert!(
        e.to_string().contains(&format!("t.dae:{line}"))
            && e.to_string().contains("no <image> with id \"nothing\""),
        "{e}"
    );
    // The texture file itself missing: located at the <texture>.
    let c = parse_collada(&text, "/no/such/dir/t.dae").unwrap();
    let e = crate::Scene::from_collada(&c, &crate::SceneOptions::default(), "/no/such/dir/t.dae")
        .unwrap_err();
    assert!(
        e.to_string()
            .contains("tex/checker.png: cannot read the texture"),
        "{e}"
    );
}
