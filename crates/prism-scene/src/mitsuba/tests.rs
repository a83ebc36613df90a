//! The Mitsuba reader against closed forms: transforms composed in document order, look-at
//! frames, defaults and `-D` values, includes and references, the camera's field of view on
//! each axis, and located errors for everything it refuses.

use std::path::PathBuf;

use prism_math::glam::{DMat4, DVec3};

use super::*;
use crate::scene::Light;
use prism_math::Rgb;

/// A scratch folder holding `files` (name, text); removed when dropped.
struct Files(PathBuf);

impl Files {
    fn new(name: &str, files: &[(&str, &str)]) -> Files {
        let dir = std::env::temp_dir().join(format!("prism-mitsuba-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        for (f, text) in files {
            std::fs::write(dir.join(f), text).unwrap();
        }
        Files(dir)
    }

    fn path(&self, f: &str) -> PathBuf {
        self.0.join(f)
    }
}

impl Drop for Files {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// A scene file around `body`, with a sensor.
fn scene(body: &str) -> String {
    format!(
        "<scene version=\"3.0.0\">\n<sensor type=\"perspective\"><float name=\"fov\" value=\"40\"/>\
         <film type=\"hdrfilm\"><integer name=\"width\" value=\"200\"/><integer name=\"height\" value=\"100\"/></film></sensor>\n{body}\n</scene>\n"
    )
}

fn read(
    name: &str,
    body: &str,
    defines: &[(&str, &str)],
) -> Result<MitsubaScene, crate::SceneError> {
    let files = Files::new(name, &[("s.xml", &scene(body))]);
    let d: Vec<(String, String)> = defines
        .iter()
        .map(|(a, b)| (a.to_string(), b.to_string()))
        .collect();
    read_mitsuba(&files.path("s.xml"), &d)
}

fn transform_of(body: &str) -> DMat4 {
    let files = Files::new(
        "t",
        &[(
            "s.xml",
            &scene(&format!(
                "<shape type=\"sphere\"><transform name=\"to_world\">{body}</transform></shape>"
            )),
        )],
    );
    let doc = read_document(&files.path("s.xml"), &[]).unwrap();
    let shape = doc.objects.iter().find(|o| o.tag == "shape").unwrap();
    match &shape.prop("to_world").unwrap().value {
        Value::Transform(m) => *m,
        v => panic!("{v:?}"),
    }
}

fn close(a: DVec3, b: DVec3) -> bool {
    (a - b).length() < 1e-12
}

/// Closed forms: each operation applies after the ones before it.
#[test]
fn transforms_compose_in_document_order() {
    let m = transform_of("<translate x=\"1\"/><rotate y=\"1\" angle=\"90\"/>");
    // (1, 0, 0) moves to (2, 0, 0), then a quarter turn about +y takes x to -z.
    assert!(
        close(m.transform_point3(DVec3::X), DVec3::new(0.0, 0.0, -2.0)),
        "{m:?}"
    );
    let m = transform_of("<rotate y=\"1\" angle=\"90\"/><translate x=\"1\"/>");
    assert!(
        close(m.transform_point3(DVec3::X), DVec3::new(1.0, 0.0, -1.0)),
        "{m:?}"
    );
    let m = transform_of("<scale value=\"2\"/><scale x=\"3\"/><translate value=\"1, 2, 3\"/>");
    assert!(
        close(m.transform_point3(DVec3::ONE), DVec3::new(7.0, 4.0, 5.0)),
        "{m:?}"
    );
    // A matrix is written row by row; nine numbers are the upper 3x3.
    let m = transform_of("<matrix value=\"1 0 0 5  0 1 0 6  0 0 1 7  0 0 0 1\"/>");
    assert!(close(
        m.transform_point3(DVec3::ZERO),
        DVec3::new(5.0, 6.0, 7.0)
    ));
    let m = transform_of("<matrix value=\"0 -1 0  1 0 0  0 0 1\"/>");
    assert!(close(m.transform_point3(DVec3::X), DVec3::Y));
}

/// Closed form of Mitsuba's look-at: +z towards the target, +y up, +x to the left.
#[test]
fn look_at_frames_the_view() {
    let m = transform_of("<lookat origin=\"0, 0, 5\" target=\"0, 0, 0\" up=\"0, 1, 0\"/>");
    assert!(close(
        m.transform_point3(DVec3::ZERO),
        DVec3::new(0.0, 0.0, 5.0)
    ));
    assert!(close(m.transform_vector3(DVec3::Z), -DVec3::Z));
    assert!(close(m.transform_vector3(DVec3::Y), DVec3::Y));
    // Seen from +z looking at -z, the viewer's left is -x.
    assert!(close(m.transform_vector3(DVec3::X), -DVec3::X));
}

/// `$name` takes its `<default>`, a `-D` value wins, and one with neither is a located
/// error naming both ways to give it.
#[test]
fn defaults_and_defines_fill_parameters() {
    let body = "<default name=\"r\" value=\"0.5\"/>\n<shape type=\"sphere\"><float name=\"radius\" value=\"$r\"/></shape>";
    let s = read("defaults", body, &[]).unwrap();
    assert_eq!(s.scene.spheres[0].radius, 0.5);
    let s = read("defines", body, &[("r", "2")]).unwrap();
    assert_eq!(s.scene.spheres[0].radius, 2.0);
    let e = read(
        "missing",
        "<shape type=\"sphere\"><float name=\"radius\" value=\"$q\"/></shape>",
        &[],
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("s.xml:3") && e.contains("$q: no value") && e.contains("-D q="),
        "{e}"
    );
}

/// Includes read in place, relative to the including file; a file that includes itself
/// stops at the depth limit with a located error.
#[test]
fn includes_read_in_place_and_cycles_stop() {
    let files = Files::new(
        "include",
        &[
            ("main.xml", &scene("<include filename=\"part.xml\"/>")),
            (
                "part.xml",
                "<scene version=\"3.0.0\"><shape type=\"sphere\"/></scene>",
            ),
            (
                "loop.xml",
                "<scene version=\"3.0.0\"><include filename=\"loop.xml\"/></scene>",
            ),
        ],
    );
    let s = read_mitsuba(&files.path("main.xml"), &[]).unwrap();
    assert_eq!(s.scene.spheres.len(), 1);
    let e = read_document(&files.path("loop.xml"), &[])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("loop.xml:1") && e.contains("nested more than"),
        "{e}"
    );
}

/// A `<ref>` may come before the object it names; one naming nothing is a located error.
#[test]
fn references_resolve_forwards_and_fail_located() {
    let s = read(
        "refs",
        "<shape type=\"sphere\"><ref id=\"red\"/></shape>\n<bsdf type=\"diffuse\" id=\"red\"><rgb name=\"reflectance\" value=\"0.8, 0.1, 0.1\"/></bsdf>",
        &[],
    )
    .unwrap();
    let m = s.scene.spheres[0].material;
    assert!(
        matches!(s.scene.materials[m], crate::Material::Diffuse { reflectance, .. } if reflectance.r == 0.8),
        "{:?}",
        s.scene.materials[m]
    );
    let e = read(
        "badref",
        "<shape type=\"sphere\"><ref id=\"nothing\"/></shape>",
        &[],
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("s.xml:3") && e.contains("\"nothing\": no object has this id"),
        "{e}"
    );
}

/// What prism does not render is a located error naming the plugin, never a silent
/// substitute; so are unknown elements and wrong property kinds.
#[test]
fn unsupported_plugins_are_located_errors() {
    for (body, want) in [
        (
            "<shape type=\"sphere\"><bsdf type=\"hair\"/></shape>",
            "<bsdf>: type=\"hair\": not supported by prism",
        ),
        (
            "<shape type=\"hyperboloid\"/>",
            "<shape>: type=\"hyperboloid\": not supported by prism",
        ),
        (
            "<emitter type=\"area\"/>",
            "an area emitter belongs inside a <shape>",
        ),
        (
            "<shape type=\"sphere\"><float name=\"radius\" value=\"x\"/></shape>",
            "expected a finite number",
        ),
        (
            "<shape type=\"sphere\"><string name=\"radius\" value=\"1\"/></shape>",
            "radius: expected a <float>, found <string>",
        ),
        ("<thing/>", "unknown element <thing>"),
    ] {
        let e = read("unsupported", body, &[]).unwrap_err().to_string();
        assert!(e.contains("s.xml:3") && e.contains(want), "{body}: {e}");
    }
    let files = Files::new("version", &[("v.xml", "<scene version=\"0.6.0\"/>")]);
    let e = read_mitsuba(&files.path("v.xml"), &[])
        .unwrap_err()
        .to_string();
    assert!(e.contains("expected a Mitsuba 2 or 3 scene"), "{e}");
}

/// Closed forms of the field of view on each `fov_axis` for a 2:1 film: `x` is the
/// horizontal angle, `y` the vertical, and the other follows from the aspect ratio.
#[test]
fn fov_axes_give_both_angles() {
    let angle = |fov: f64, axis: &str| {
        let files = Files::new(
            &format!("fov-{axis}"),
            &[(
                "s.xml",
                &format!(
                    "<scene version=\"3.0.0\"><sensor type=\"perspective\"><float name=\"fov\" value=\"{fov}\"/>\
                     <string name=\"fov_axis\" value=\"{axis}\"/><film type=\"hdrfilm\"><integer name=\"width\" value=\"200\"/>\
                     <integer name=\"height\" value=\"100\"/></film></sensor></scene>"
                ),
            )],
        );
        let c = read_mitsuba(&files.path("s.xml"), &[])
            .unwrap()
            .scene
            .camera;
        (f64::from(c.hfov), f64::from(c.vfov))
    };
    let half = |deg: f64| (deg.to_radians() / 2.0).tan();
    let (h, v) = angle(60.0, "x");
    assert!((h - 60.0).abs() < 1e-4 && (half(v) - half(60.0) / 2.0).abs() < 1e-6);
    let (h, v) = angle(30.0, "y");
    assert!((v - 30.0).abs() < 1e-4 && (half(h) - half(30.0) * 2.0).abs() < 1e-6);
    // On a wide film the smaller side is the height, the larger the width.
    assert_eq!(angle(30.0, "smaller"), angle(30.0, "y"));
    assert_eq!(angle(30.0, "larger"), angle(30.0, "x"));
    let (h, v) = angle(50.0, "diagonal");
    let d = (half(h).powi(2) + half(v).powi(2)).sqrt();
    assert!((d - half(50.0)).abs() < 1e-6 && (half(h) / half(v) - 2.0).abs() < 1e-6);
}

/// Mitsuba's shapes and lights land where Mitsuba puts them: a scaled rectangle's area and
/// facing, a point light's position through to_world, a sphere's radius under a uniform
/// scale; a sphere under a stretch is refused.
#[test]
fn shapes_and_lights_are_placed() {
    let s = read(
        "shapes",
        "<shape type=\"rectangle\"><transform name=\"to_world\"><scale value=\"2\"/><rotate x=\"1\" angle=\"90\"/></transform></shape>\n\
         <emitter type=\"point\"><transform name=\"to_world\"><translate y=\"3\"/></transform><rgb name=\"intensity\" value=\"2\"/></emitter>\n\
         <shape type=\"sphere\"><float name=\"radius\" value=\"0.5\"/><transform name=\"to_world\"><scale value=\"4\"/></transform></shape>",
        &[],
    )
    .unwrap();
    let m = &s.scene.meshes[0];
    let area: f32 = m
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| m.positions[i as usize]);
            0.5 * (b - a).cross(c - a).length()
        })
        .sum();
    assert!((area - 16.0).abs() < 1e-5, "{area}");
    // +z turned a quarter about +x faces -y.
    let [a, b, c] = m.triangles[0].map(|i| m.positions[i as usize]);
    assert!((b - a).cross(c - a).normalize().dot(-prism_math::Vec3::Y) > 0.999);
    assert!(
        matches!(s.scene.lights[0], Light::Point { position, .. } if position == prism_math::Vec3::new(0.0, 3.0, 0.0))
    );
    assert_eq!(s.scene.spheres[0].radius, 2.0);
    let e = read(
        "stretch",
        "<shape type=\"sphere\"><transform name=\"to_world\"><scale x=\"2\"/></transform></shape>",
        &[],
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("keep the sphere round"), "{e}");
}

/// Mitsuba's conductor presets: `material` names one (Mitsuba's RGB eta and k for gold),
/// the default is `none` (eta 0, k 1: everything reflected), explicit `eta`/`k` win, and an
/// unknown name is a located error.
#[test]
fn conductor_materials_are_mitsubas() {
    let material = |body: &str| {
        let s = read(
            "conductor",
            &format!("<shape type=\"sphere\">{body}</shape>"),
            &[],
        )
        .unwrap();
        s.scene.materials[s.scene.spheres[0].material].clone()
    };
    let gold =
        material("<bsdf type=\"roughconductor\"><string name=\"material\" value=\"Au\"/></bsdf>");
    assert!(
        matches!(gold, crate::Material::Microfacet { alpha, eta, k } if alpha == 0.1 && eta.b == 1.44205 && k.r == 3.983),
        "{gold:?}"
    );
    let none = material("<bsdf type=\"roughconductor\"/>");
    assert!(
        matches!(none, crate::Material::Microfacet { eta, k, .. } if eta.g == 0.0 && k.g == 1.0),
        "{none:?}"
    );
    let given = material("<bsdf type=\"roughconductor\"><string name=\"material\" value=\"Au\"/><rgb name=\"eta\" value=\"2\"/></bsdf>");
    assert!(
        matches!(given, crate::Material::Microfacet { eta, .. } if eta.r == 2.0),
        "{given:?}"
    );
    let e = read("conductor-bad", "<shape type=\"sphere\"><bsdf type=\"roughconductor\"><string name=\"material\" value=\"Unobtainium\"/></bsdf></shape>", &[])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("s.xml:3") && e.contains("no such conductor"),
        "{e}"
    );
    assert_eq!(super::CONDUCTORS.len(), 40);
}

/// A spot light is read as Mitsuba places it: at its `to_world`'s origin, its axis the
/// local +z, `beam_width` three quarters of `cutoff_angle` unless given.
#[test]
fn spot_lights_are_placed() {
    let s = read(
        "spot",
        "<emitter type=\"spot\"><transform name=\"to_world\"><lookat origin=\"0, 2, 0\" target=\"0, 0, 0\" up=\"0, 0, 1\"/></transform><float name=\"cutoff_angle\" value=\"40\"/></emitter>",
        &[],
    )
    .unwrap();
    let Light::Spot {
        position,
        to_local,
        cutoff,
        beam_width,
        ..
    } = s.scene.lights[0]
    else {
        panic!("{:?}", s.scene.lights[0])
    };
    assert_eq!(position, prism_math::Vec3::new(0.0, 2.0, 0.0));
    assert!((to_local * -prism_math::Vec3::Y - prism_math::Vec3::Z).length() < 1e-6);
    assert_eq!((cutoff, beam_width), (40.0, 30.0));
}

/// `plastic` is read with Mitsuba's defaults: diffuse 0.5, specular 1, polypropylene (1.49)
/// over air (1.000277); `nonlinear` is refused.
#[test]
fn plastic_is_read_with_mitsubas_defaults() {
    let s = read(
        "plastic",
        "<shape type=\"sphere\"><bsdf type=\"plastic\"/></shape>",
        &[],
    )
    .unwrap();
    let m = s.scene.materials[s.scene.spheres[0].material].clone();
    assert!(
        matches!(m, crate::Material::Plastic { diffuse, specular, eta, .. } if diffuse.r == 0.5 && specular.g == 1.0 && (eta - 1.49 / 1.000_277).abs() < 1e-6),
        "{m:?}"
    );
    let s = read("plastic-nl", "<shape type=\"sphere\"><bsdf type=\"plastic\"><boolean name=\"nonlinear\" value=\"true\"/></bsdf></shape>", &[])
        .unwrap();
    let m = &s.scene.materials[s.scene.spheres[0].material];
    assert!(
        matches!(
            m,
            crate::Material::Plastic {
                nonlinear: true,
                ..
            }
        ),
        "{m:?}"
    );
    let e = read("plastic-nl-tex", "<shape type=\"sphere\"><bsdf type=\"plastic\"><boolean name=\"nonlinear\" value=\"true\"/><texture type=\"checkerboard\" name=\"diffuse_reflectance\"/></bsdf></shape>", &[])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("nonlinear with a textured diffuse_reflectance: not supported"),
        "{e}"
    );
}

/// `thindielectric` is read with Mitsuba's defaults: bk7 (1.5046) over air (1.000277).
#[test]
fn thin_dielectric_is_read_with_mitsubas_defaults() {
    let s = read(
        "thin",
        "<shape type=\"rectangle\"><bsdf type=\"thindielectric\"/></shape>",
        &[],
    )
    .unwrap();
    let m = s.scene.materials[s.scene.meshes[0].material].clone();
    assert!(
        matches!(m, crate::Material::ThinDielectric { ior, .. } if (ior - 1.5046 / 1.000_277).abs() < 1e-6),
        "{m:?}"
    );
}

/// Hostile input: a `to_world` that scales a shape past the largest float is a located error,
/// not infinite geometry handed to the renderer.
#[test]
fn shapes_beyond_the_finite_numbers_are_refused() {
    for shape in ["rectangle", "sphere"] {
        let e = read(
            "inf",
            &format!("<shape type=\"{shape}\"><transform name=\"to_world\"><scale value=\"1e30\"/><scale value=\"1e30\"/></transform></shape>"),
            &[],
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("s.xml:3") && e.contains("beyond the finite numbers"),
            "{shape}: {e}"
        );
    }
}

/// Mitsuba's microfacet parameters: `distribution` (Beckmann by default, GGX), `alpha`
/// (0.1) or `alpha_u` with `alpha_v`, a zero roughness clamped to 1e-4; `alpha` with
/// `alpha_u`, or `alpha_u` alone, is a located error, as Mitsuba throws.
#[test]
fn microfacet_parameters_are_mitsubas() {
    let material = |body: &str| {
        let s = read(
            "rough",
            &format!("<shape type=\"sphere\">{body}</shape>"),
            &[],
        )
        .unwrap();
        s.scene.materials[s.scene.spheres[0].material].clone()
    };
    let ggx = material("<bsdf type=\"roughconductor\"><string name=\"distribution\" value=\"GGX\"/><float name=\"alpha_u\" value=\"0.2\"/><float name=\"alpha_v\" value=\"0\"/></bsdf>");
    assert!(
        matches!(ggx, crate::Material::Conductor { roughness: Some(crate::Roughness { kind: crate::MicrofacetKind::Ggx, alpha_u, alpha_v }), .. } if alpha_u == 0.2 && alpha_v == 1e-4),
        "{ggx:?}"
    );
    let glass = material(
        "<bsdf type=\"roughdielectric\"><string name=\"int_ior\" value=\"water\"/></bsdf>",
    );
    assert!(
        matches!(glass, crate::Material::RoughDielectric { roughness: crate::Roughness { kind: crate::MicrofacetKind::Beckmann, alpha_u, .. }, ior, .. } if alpha_u == 0.1 && (ior - 1.333 / 1.000_277).abs() < 1e-6),
        "{glass:?}"
    );
    let smooth =
        material("<bsdf type=\"conductor\"><string name=\"material\" value=\"Ag\"/></bsdf>");
    assert!(
        matches!(
            smooth,
            crate::Material::Conductor {
                roughness: None,
                ..
            }
        ),
        "{smooth:?}"
    );
    for bad in [
        "<float name=\"alpha\" value=\"0.1\"/><float name=\"alpha_u\" value=\"0.1\"/><float name=\"alpha_v\" value=\"0.1\"/>",
        "<float name=\"alpha_u\" value=\"0.1\"/>",
        "<string name=\"distribution\" value=\"phong\"/>",
    ] {
        let e = read(
            "rough-bad",
            &format!("<shape type=\"sphere\"><bsdf type=\"roughdielectric\">{bad}</bsdf></shape>"),
            &[],
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("s.xml:3:") && e.contains("roughdielectric"), "{e}");
    }
}

/// Mitsuba's textures: a bitmap (with `filter_type`, `wrap_mode`, `to_uv`) or checkerboard
/// in place of a diffuse reflectance (or a plastic's), inline or by reference; the
/// checkerboard is color0
/// where u and v fall in the same half of the unit square (a 2x2 image looked up nearest).
/// A texture elsewhere, or a bitmap that is no image, is a located error.
#[test]
fn textures_are_read_as_mitsuba_reads_them() {
    let dir = std::env::temp_dir().join(format!("prism-mitsuba-tex-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let png = prism_image::encode_png(&prism_image::Rgb8Image::new(2, 1, [255, 0, 0])).unwrap();
    std::fs::write(dir.join("red.png"), png).unwrap();
    std::fs::write(dir.join("not.png"), b"not an image").unwrap();
    let read_in = |body: &str| -> Result<crate::Scene, String> {
        let file = dir.join("s.xml");
        std::fs::write(&file, scene(body)).unwrap();
        crate::mitsuba::read_mitsuba(&file, &[])
            .map(|m| m.scene)
            .map_err(|e| e.to_string())
    };
    let s = read_in(r#"<texture type="checkerboard" id="c"><rgb name="color0" value="1 0 0"/><transform name="to_uv"><scale x="4" y="2"/></transform></texture>
        <shape type="rectangle"><bsdf type="diffuse"><ref name="reflectance" id="c"/></bsdf></shape>"#).unwrap();
    let crate::Material::Diffuse {
        reflectance,
        texture: Some(t),
    } = &s.materials[s.meshes[0].material]
    else {
        panic!("{:?}", s.materials);
    };
    assert_eq!(*reflectance, Rgb::WHITE);
    assert_eq!(t.to_uv, [4.0, 0.0, 0.0, 0.0, 2.0, 0.0]);
    assert_eq!(t.sampling, prism_image::PixelSampling::Nearest);
    assert_eq!(
        (t.image.get(0, 0), t.image.get(1, 1)),
        (Rgb::new(1.0, 0.0, 0.0), Rgb::new(1.0, 0.0, 0.0))
    );
    assert_eq!(
        (t.image.get(1, 0), t.image.get(0, 1)),
        (Rgb::splat(0.2), Rgb::splat(0.2))
    );
    let s = read_in(r#"<shape type="rectangle"><bsdf type="diffuse"><texture type="bitmap" name="reflectance"><string name="filename" value="red.png"/><string name="wrap_mode" value="mirror"/><string name="filter_type" value="nearest"/></texture></bsdf></shape>"#).unwrap();
    let crate::Material::Diffuse {
        texture: Some(t), ..
    } = &s.materials[s.meshes[0].material]
    else {
        panic!("{:?}", s.materials);
    };
    assert_eq!(t.wrap, prism_image::Wrap::Mirror);
    let s = read_in(r#"<shape type="rectangle"><bsdf type="roughplastic"><texture type="checkerboard" name="diffuse_reflectance"/></bsdf></shape>"#).unwrap();
    assert!(
        matches!(&s.materials[s.meshes[0].material], crate::Material::RoughPlastic { diffuse, texture: Some(_), .. } if *diffuse == Rgb::WHITE)
    );
    assert_eq!(t.image.get(1, 0), Rgb::new(1.0, 0.0, 0.0));
    for (body, want) in [
        (
            r#"<shape type="rectangle"><bsdf type="diffuse"><texture type="bitmap" name="reflectance"><string name="filename" value="not.png"/></texture></bsdf></shape>"#,
            "not.png",
        ),
        (
            r#"<shape type="rectangle"><bsdf type="roughconductor"><texture type="checkerboard" name="k"/></bsdf></shape>"#,
            "not supported",
        ),
        (
            r#"<shape type="rectangle"><bsdf type="diffuse"><texture type="bitmap" name="reflectance"><string name="filename" value="missing.png"/></texture></bsdf></shape>"#,
            "missing.png",
        ),
    ] {
        let e = read_in(body).unwrap_err();
        assert!(e.contains("s.xml:") && e.contains(want), "{e}");
    }
}

/// Instancing: each `instance` places the shapes of its `shapegroup` by its own `to_world`
/// and then theirs (copies of the geometry); the group itself draws nothing; an instance
/// of anything but one shapegroup is a located error.
#[test]
fn instances_place_copies_of_their_shapegroup() {
    let s = read(
        "instance",
        r#"<shape type="shapegroup" id="g">
            <shape type="rectangle"><transform name="to_world"><translate x="1"/></transform></shape>
            <shape type="sphere"><float name="radius" value="0.5"/></shape>
        </shape>
        <shape type="instance"><ref id="g"/><transform name="to_world"><translate y="2"/></transform></shape>
        <shape type="instance"><ref id="g"/><transform name="to_world"><scale value="2"/></transform></shape>"#,
        &[],
    )
    .unwrap()
    .scene;
    assert_eq!((s.meshes.len(), s.spheres.len()), (2, 2));
    let min_x = |m: &crate::TriangleMesh| m.positions.iter().map(|p| p.x).fold(f32::MAX, f32::min);
    assert_eq!(min_x(&s.meshes[0]), 0.0);
    assert_eq!(s.meshes[0].positions[0].y, 1.0);
    assert_eq!(min_x(&s.meshes[1]), 0.0);
    assert_eq!(s.meshes[1].positions[0].y, -2.0);
    assert_eq!((s.spheres[0].center.y, s.spheres[0].radius), (2.0, 0.5));
    assert_eq!((s.spheres[1].center.y, s.spheres[1].radius), (0.0, 1.0));
    let e = read(
        "instance-bad",
        r#"<bsdf type="diffuse" id="d"/><shape type="instance"><ref id="d"/></shape>"#,
        &[],
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("s.xml:") && e.contains("shapegroup"), "{e}");
}

/// `--lenient`: what prism does not render is read past with one warning per kind (a grey
/// diffuse for a BSDF, left out for a shape or other plugin, the path tracer for an
/// integrator); strict reading refuses the first of them, located; errors that are not
/// refusals (a missing file) stay errors.
#[test]
fn lenient_reading_stands_in_and_warns_once_per_kind() {
    let body = r#"<integrator type="volpath"/>
        <bsdf type="hair" id="h"/>
        <shape type="sphere"><ref id="h"/></shape>
        <shape type="rectangle"><bsdf type="hair"/></shape>
        <shape type="hair"/>
        <shape type="hair"/>
        <medium type="homogeneous"/>"#;
    let e = read("lenient", body, &[]).unwrap_err();
    assert!(matches!(e, crate::SceneError::Unsupported { .. }), "{e}");
    let dir = std::env::temp_dir().join(format!("prism-mitsuba-lenient-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("s.xml");
    std::fs::write(&file, scene(body)).unwrap();
    let s = crate::mitsuba::read_mitsuba_with(&file, &[], lenient())
        .unwrap()
        .scene;
    assert_eq!((s.spheres.len(), s.meshes.len()), (1, 1));
    let grey = &s.materials[s.spheres[0].material];
    assert!(
        matches!(grey, crate::Material::Diffuse { reflectance, texture: None } if *reflectance == Rgb::splat(0.5))
    );
    let messages: Vec<&str> = s.warnings.iter().map(|w| w.message.as_str()).collect();
    assert_eq!(messages.len(), 4, "{messages:?}");
    assert!(
        messages.iter().all(|m| m.ends_with("(--lenient)")),
        "{messages:?}"
    );
    std::fs::write(
        &file,
        scene(r#"<shape type="obj"><string name="filename" value="missing.obj"/></shape>"#),
    )
    .unwrap();
    assert!(crate::mitsuba::read_mitsuba_with(&file, &[], lenient()).is_err());
}

/// Mitsuba's orthographic sensor: parallel rays from its near plane, its film spanning
/// to_world's x axis twice across and y axis twice (over the aspect) up.
#[test]
fn orthographic_sensors_keep_their_extents() {
    let dir = std::env::temp_dir().join(format!("prism-mitsuba-ortho-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("s.xml");
    std::fs::write(
        &file,
        r#"<scene version="3.0.0"><sensor type="orthographic"><float name="near_clip" value="0.5"/>
            <transform name="to_world"><scale x="2" y="3"/><lookat origin="0, 0, 4" target="0, 0, 0" up="0, 1, 0"/></transform>
            <film type="hdrfilm"><integer name="width" value="64"/><integer name="height" value="32"/></film></sensor></scene>"#,
    )
    .unwrap();
    let c = crate::mitsuba::read_mitsuba(&file, &[])
        .unwrap()
        .scene
        .camera;
    assert_eq!(c.orthographic, Some((2.0, 3.0)));
    assert!(
        (c.eye - prism_math::Vec3::new(0.0, 0.0, 3.5)).length() < 1e-6,
        "{}",
        c.eye
    );
}

/// `<path value>` adds a folder file names are also looked for in (Mitsuba's docs scenes
/// keep their meshes in a shared folder), relative to the file it is in; a nested plugin
/// prism does not read in place of a property (a spot light's texture) is refused, not
/// ignored.
#[test]
fn search_paths_resolve_files_and_nested_plugins_are_refused() {
    let dir = std::env::temp_dir().join(format!("prism-mitsuba-path-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("common/meshes")).unwrap();
    std::fs::create_dir_all(dir.join("scenes")).unwrap();
    std::fs::write(
        dir.join("common/meshes/tri.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    )
    .unwrap();
    let file = dir.join("scenes/s.xml");
    std::fs::write(
        &file,
        scene(r#"<path value="../common"/><shape type="obj"><string name="filename" value="meshes/tri.obj"/></shape>"#),
    )
    .unwrap();
    let s = crate::mitsuba::read_mitsuba(&file, &[]).unwrap().scene;
    assert_eq!(s.meshes[0].triangles.len(), 1);
    std::fs::write(
        &file,
        scene(r#"<emitter type="spot"><texture type="checkerboard" name="texture"/></emitter>"#),
    )
    .unwrap();
    let e = crate::mitsuba::read_mitsuba(&file, &[])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("s.xml:") && e.contains("checkerboard") && e.contains("spot"),
        "{e}"
    );
}

/// `blendbsdf` and `mask` are read as choices among their nested BSDFs, which are translated
/// first: Mitsuba's defaults (opacity 0.5; a blend's weight is required), `twosided` around
/// a blend making it two-sided, a checkerboard read for a number with its colours swapped
/// (Mitsuba's `eval_1`), and located errors for a wrong number of nested BSDFs or a cycle.
#[test]
fn blends_and_masks_are_read_as_choices() {
    let s = read(
        "blend",
        "<shape type=\"sphere\"><bsdf type=\"twosided\"><bsdf type=\"blendbsdf\"><float name=\"weight\" value=\"0.25\"/>\
         <bsdf type=\"diffuse\"/><bsdf type=\"conductor\"/></bsdf></bsdf></shape>\
         <shape type=\"sphere\"><bsdf type=\"mask\"><bsdf type=\"diffuse\"/></bsdf></shape>\
         <shape type=\"sphere\"><bsdf type=\"mask\"><texture type=\"checkerboard\" name=\"opacity\"><float name=\"color0\" value=\"1\"/><float name=\"color1\" value=\"0\"/></texture><bsdf type=\"diffuse\"/></bsdf></shape>",
        &[],
    )
    .unwrap();
    let materials = &s.scene.materials;
    let blend = s.scene.spheres[0].material;
    let crate::Material::Blend {
        weight: crate::ScalarTexture::Constant(w),
        materials: [a, b],
    } = materials[blend]
    else {
        panic!("{:?}", materials[blend]);
    };
    assert_eq!(w, 0.25);
    assert!(matches!(materials[a], crate::Material::Diffuse { .. }));
    assert!(matches!(materials[b], crate::Material::Mirror { .. }));
    assert!(a < blend && b < blend);
    assert!(!s.scene.one_sided[blend] && s.scene.one_sided[a]);
    let mask = s.scene.spheres[1].material;
    assert!(
        matches!(materials[mask], crate::Material::Mask { opacity: crate::ScalarTexture::Constant(o), .. } if o == 0.5),
        "{:?}",
        materials[mask]
    );
    let crate::Material::Mask {
        opacity: crate::ScalarTexture::Image(ref t),
        ..
    } = materials[s.scene.spheres[2].material]
    else {
        panic!("{:?}", materials[s.scene.spheres[2].material]);
    };
    // color0 (1) where u and v fall in different halves: texels (1, 0) and (0, 1).
    assert_eq!(t.image.get(1, 0), Rgb::splat(1.0));
    assert_eq!(t.image.get(0, 1), Rgb::splat(1.0));
    assert_eq!(t.image.get(0, 0), Rgb::splat(0.0));

    for (body, wanted) in [
        (
            "<bsdf type=\"blendbsdf\"><float name=\"weight\" value=\"0.5\"/><bsdf type=\"diffuse\"/></bsdf>",
            "s.xml:4: <bsdf>: type=\"blendbsdf\": expected 2 nested <bsdf>, found 1",
        ),
        (
            "<bsdf type=\"blendbsdf\"><bsdf type=\"diffuse\"/><bsdf type=\"diffuse\"/></bsdf>",
            "expected a weight",
        ),
        (
            "<bsdf type=\"mask\"><rgb name=\"opacity\" value=\"0.5\"/><bsdf type=\"diffuse\"/><bsdf type=\"diffuse\"/></bsdf>",
            "expected 1 nested <bsdf>, found 2",
        ),
        (
            "<bsdf type=\"mask\"><texture type=\"bitmap\" name=\"weight\"/><bsdf type=\"diffuse\"/></bsdf>",
            "not supported by prism yet (a bitmap or checkerboard as its opacity is)",
        ),
    ] {
        let e = read(
            "blend-bad",
            &format!("<shape type=\"sphere\">\n{body}\n</shape>"),
            &[],
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains(wanted), "{e}");
    }
    let e = read(
        "mask-cycle",
        "<bsdf type=\"mask\" id=\"m\"><ref id=\"m\"/></bsdf><shape type=\"sphere\"><ref id=\"m\"/></shape>",
        &[],
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("nested more than"), "{e}");
}

/// `normalmap` and `bumpmap` are read with Mitsuba's defaults (`scale` 1, the flip of
/// invalid normals and the shadowing term on), and refused with located errors where prism
/// or Mitsuba cannot render them: a bump map's texture other than a bitmap, a map over a
/// blend, and a wrong number of children.
#[test]
fn bump_and_normal_maps_are_read_with_mitsubas_defaults() {
    let files = Files::new(
        "maps",
        &[(
            "s.xml",
            &scene(
                "<shape type=\"sphere\"><bsdf type=\"bumpmap\"><texture type=\"bitmap\"><string name=\"filename\" value=\"h.exr\"/></texture><bsdf type=\"diffuse\"/></bsdf></shape>\
                 <shape type=\"sphere\"><bsdf type=\"normalmap\"><boolean name=\"use_shadowing_function\" value=\"false\"/><texture type=\"bitmap\" name=\"normalmap\"><string name=\"filename\" value=\"h.exr\"/></texture><bsdf type=\"diffuse\"/></bsdf></shape>",
            ),
        )],
    );
    let mut image = prism_image::RgbImage::new(2, 2, Rgb::splat(0.5));
    image.set(1, 0, Rgb::WHITE);
    prism_image::write_exr(&files.path("h.exr"), &image).unwrap();
    let s = read_mitsuba(&files.path("s.xml"), &[]).unwrap();
    let m = &s.scene.materials;
    assert!(
        matches!(&m[s.scene.spheres[0].material], crate::Material::BumpMap { scale, tilt, .. } if *scale == 1.0 && tilt.flip_invalid_normals && tilt.shadowing),
        "{:?}",
        m[s.scene.spheres[0].material]
    );
    assert!(
        matches!(&m[s.scene.spheres[1].material], crate::Material::NormalMap { normals, tilt, .. } if normals.image.get(1, 0) == Rgb::WHITE && !tilt.shadowing),
        "{:?}",
        m[s.scene.spheres[1].material]
    );
    for (body, wanted) in [
        (
            "<bsdf type=\"bumpmap\"><texture type=\"checkerboard\"/><bsdf type=\"diffuse\"/></bsdf>",
            "expected a bitmap (Mitsuba has no gradient for others)",
        ),
        (
            "<bsdf type=\"normalmap\"><bsdf type=\"diffuse\"/></bsdf>",
            "s.xml:4: <bsdf>: type=\"normalmap\": expected one nested <bsdf> and one texture, found 1 and 0",
        ),
        (
            "<bsdf type=\"bumpmap\"><texture type=\"bitmap\"><string name=\"filename\" value=\"h.exr\"/></texture>\n<bsdf type=\"mask\"><bsdf type=\"diffuse\"/></bsdf></bsdf>",
            "s.xml:5: <bsdf>: type=\"mask\" in type=\"bumpmap\": a blend, mask or map under a map: not supported by prism yet",
        ),
    ] {
        let files = Files::new(
            "maps-bad",
            &[("s.xml", &scene(&format!("<shape type=\"sphere\">\n{body}\n</shape>")))],
        );
        prism_image::write_exr(&files.path("h.exr"), &image).unwrap();
        let e = read_mitsuba(&files.path("s.xml"), &[]).unwrap_err().to_string();
        assert!(e.contains(wanted), "{e}");
    }
}

/// `principled` is read with Mitsuba's defaults (base colour and roughness 0.5, `specular`
/// 0.5 as an index of 2 / (1 - sqrt(0.04)) - 1 = 1.5), `eta` given directly (an index of 1
/// moved to 1.001 under transmission), and `eta` with `specular` refused.
#[test]
fn principled_is_read_with_mitsubas_defaults() {
    let s = read(
        "principled",
        "<shape type=\"sphere\"><bsdf type=\"principled\"/></shape>\
         <shape type=\"sphere\"><bsdf type=\"principled\"><float name=\"eta\" value=\"1\"/><float name=\"spec_trans\" value=\"0.5\"/></bsdf></shape>",
        &[],
    )
    .unwrap();
    let m = &s.scene.materials;
    let crate::Material::Principled {
        base_color,
        roughness,
        eta,
        two_sided,
        ..
    } = m[s.scene.spheres[0].material]
    else {
        panic!("{:?}", m[s.scene.spheres[0].material]);
    };
    assert_eq!(
        (base_color, roughness, two_sided),
        (Rgb::splat(0.5), 0.5, false)
    );
    assert!((eta - 1.5).abs() < 1e-6, "{eta}");
    assert!(
        matches!(m[s.scene.spheres[1].material], crate::Material::Principled { eta, .. } if eta == 1.001)
    );
    let e = read(
        "principled-both",
        "<shape type=\"sphere\"><bsdf type=\"principled\"><float name=\"eta\" value=\"1.3\"/><float name=\"specular\" value=\"0.3\"/></bsdf></shape>",
        &[],
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("eta and specular: expected one of them"), "{e}");
}

/// A film's crop window is read as Mitsuba's (`crop_width` and `crop_height` default to the
/// film's size, the offsets to 0) and refused, located, where it leaves the film.
#[test]
fn film_crops_must_lie_within_the_film() {
    let film = |crop: &str| {
        format!(
            "<scene version=\"3.0.0\">\n<sensor type=\"perspective\">\
             <film type=\"hdrfilm\"><integer name=\"width\" value=\"64\"/><integer name=\"height\" value=\"32\"/>{crop}</film></sensor>\n</scene>\n"
        )
    };
    let files = Files::new(
        "crop",
        &[(
            "s.xml",
            &film("<integer name=\"crop_offset_y\" value=\"8\"/><integer name=\"crop_height\" value=\"24\"/>"),
        )],
    );
    let s = read_mitsuba(&files.path("s.xml"), &[]).unwrap();
    assert_eq!(s.settings.size, (64, 24));
    assert_eq!(
        s.scene.camera.crop,
        Some(crate::Crop {
            offset: (0, 8),
            full: (64, 32)
        })
    );
    let files = Files::new(
        "crop-out",
        &[(
            "s.xml",
            &film("<integer name=\"crop_offset_x\" value=\"8\"/>"),
        )],
    );
    let e = read_mitsuba(&files.path("s.xml"), &[])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("s.xml:2: <film>: type=\"hdrfilm\": the crop window (64x32 at 8, 0) must lie within the 64x32 film"),
        "{e}"
    );
}

/// Lenient reading, of the first sensor.
fn lenient() -> crate::mitsuba::MitsubaOptions {
    crate::mitsuba::MitsubaOptions {
        lenient: true,
        sensor: 0,
    }
}

/// Textures as specular scales and alphas are read as a textured wrapper around the plain
/// material: `alpha` gives both alphas, a plastic's placeholder specular scale is its
/// texture's mean (what Mitsuba weighs its lobes by), and a texture where Mitsuba takes
/// none (a conductor's `eta`) is refused, located.
#[test]
fn textured_parameters_wrap_the_plain_material() {
    let s = read(
        "params",
        "<shape type=\"sphere\"><bsdf type=\"roughconductor\"><texture type=\"checkerboard\" name=\"alpha\"/><texture type=\"checkerboard\" name=\"specular_reflectance\"><rgb name=\"color0\" value=\"1\"/><rgb name=\"color1\" value=\"0\"/></texture></bsdf></shape>\
         <shape type=\"sphere\"><bsdf type=\"plastic\"><texture type=\"checkerboard\" name=\"specular_reflectance\"><rgb name=\"color0\" value=\"1\"/><rgb name=\"color1\" value=\"0\"/></texture></bsdf></shape>",
        &[],
    )
    .unwrap();
    let m = &s.scene.materials;
    let crate::Material::Textured { material, textures } = &m[s.scene.spheres[0].material] else {
        panic!("{:?}", m[s.scene.spheres[0].material]);
    };
    let params: Vec<_> = textures.iter().map(|(p, _)| *p).collect();
    use crate::TexturedParameter::*;
    assert_eq!(params, [AlphaU, AlphaV, SpecularReflectance]);
    assert!(matches!(m[*material], crate::Material::Conductor { .. }));
    let crate::Material::Textured { material, .. } = &m[s.scene.spheres[1].material] else {
        panic!("{:?}", m[s.scene.spheres[1].material]);
    };
    assert!(
        matches!(m[*material], crate::Material::Plastic { specular, .. } if specular == Rgb::splat(0.5)),
        "{:?}",
        m[*material]
    );
    let e = read(
        "params-eta",
        "<shape type=\"sphere\">\n<bsdf type=\"conductor\">\n<texture type=\"checkerboard\" name=\"eta\"/></bsdf></shape>",
        &[],
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("s.xml:5: <texture>: type=\"checkerboard\" in"),
        "{e}"
    );
}
