//! Tests of the scene reader: the staged files' values, overrides, and a located error for
//! every kind of bad input.

use super::*;

const PINNED2: &str = r#"{
  "cloth": {
    "damping": 0.2, "density": 150.0, "ks": 5000.0,
    "enable_structural": true, "enable_shearing": true, "enable_bending": true,
    "orientation": 0, "width": 1, "height": 1,
    "num_width_points": 50, "num_height_points": 50,
    "thickness": 0.0095,
    "pinned": [[0, 0], [49, 0]]
  }
}"#;

/// Closed form: the values as written; the thickness through a 32-bit float; overrides
/// replace values before they are checked.
#[test]
fn values_and_overrides() {
    let s = parse_scene(PINNED2, "p.json", &[]).unwrap();
    assert_eq!(s.cloth.num_width_points, 50);
    assert_eq!(s.cloth.pinned, vec![[0, 0], [49, 0]]);
    assert_eq!(s.cloth.thickness, f64::from(0.0095f32));
    assert_ne!(s.cloth.thickness, 0.0095);
    assert!(s.sphere.is_none() && s.plane.is_none());
    let s = parse_scene(
        PINNED2,
        "p.json",
        &["ks=500".into(), "cloth.density=15".into()],
    )
    .unwrap();
    assert_eq!((s.cloth.ks, s.cloth.density), (500.0, 15.0));
    let e = parse_scene(PINNED2, "p.json", &["ks".into()]).unwrap_err();
    assert_eq!(e.to_string(), "--set ks: expected KEY=VALUE");
    let e = parse_scene(PINNED2, "p.json", &["sphere.radius=1".into()]).unwrap_err();
    assert!(e.to_string().contains("no \"sphere\""), "{e}");
    let e = parse_scene(PINNED2, "p.json", &["ks=-1".into()]).unwrap_err();
    assert!(
        e.to_string()
            .contains("ks: expected a spring constant from 0 to 1e12"),
        "{e}"
    );
}

/// Every kind of bad input names the line and what was expected.
#[test]
fn bad_scenes_are_located() {
    let with = |from: &str, to: &str| PINNED2.replacen(from, to, 1);
    let cases = [
        (
            with("\"ks\": 5000.0", "\"ks\": \"stiff\""),
            "p.json:3: ks: expected a number, found a string",
        ),
        (
            with("\"ks\": 5000.0,", ""),
            "p.json:2: cloth: missing required key \"ks\"",
        ),
        (
            with("\"damping\"", "\"dampin\""),
            "p.json:3: cloth: unknown key \"dampin\"",
        ),
        (
            with("\"width\": 1", "\"width\": -1"),
            "p.json:5: width: expected a number above 0, found -1",
        ),
        (
            with("\"num_width_points\": 50", "\"num_width_points\": 0"),
            "p.json:6: num_width_points: expected 2 to 4096 masses, found 0",
        ),
        (
            with("\"num_width_points\": 50", "\"num_width_points\": 100000"),
            "p.json:6: num_width_points: expected 2 to 4096 masses",
        ),
        (
            with("[49, 0]", "[50, 0]"),
            "p.json:8: pinned: [50, 0] is outside the 50 x 50 grid",
        ),
        (
            with("\"orientation\": 0", "\"orientation\": 2"),
            "p.json:5: orientation: expected 0 (horizontal) or 1 (vertical), found 2",
        ),
        (
            with("\"num_width_points\": 50", "\"num_width_points\": 2.5"),
            "p.json:6: num_width_points: expected an integer, found 2.5",
        ),
        (
            with("{\n  \"cloth\"", "{\n  \"wind\": {}, \"cloth\""),
            "p.json:2: the top level: unknown key \"wind\"",
        ),
        (
            "{\"cloth\": {\"width\": 1".to_string(),
            "p.json:1: expected ',' or '}', found the end of the file",
        ),
        (
            "{}".to_string(),
            "p.json:1: the top level: missing required key \"cloth\"",
        ),
    ];
    for (text, want) in cases {
        let e = parse_scene(&text, "p.json", &[]).unwrap_err().to_string();
        assert!(e.starts_with(want), "\n got: {e}\nwant: {want}");
    }
    let sphere = |r: &str| {
        format!(
            "{{\"sphere\": {{\"origin\": [0,0,0], \"radius\": {r}, \"friction\": 0.3}}, {}",
            &PINNED2[1..]
        )
    };
    let e = parse_scene(&sphere("0"), "p.json", &[])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("radius: expected a radius above 0 and at most 1e6, found 0"),
        "{e}"
    );
    let plane = format!(
        "{{\"plane\": {{\"point\": [0,0,0], \"normal\": [0,0,0], \"friction\": 0.5}}, {}",
        &PINNED2[1..]
    );
    let e = parse_scene(&plane, "p.json", &[]).unwrap_err().to_string();
    assert!(e.contains("normal: expected a non-zero vector"), "{e}");
}

/// The staged scenes all read.
#[test]
fn staged_scenes_read() {
    for name in ["pinned2", "pinned4", "plane", "sphere", "selfCollision"] {
        let path = prism_testkit::shared_asset(&format!("clothsim/scene/{name}.json"));
        let s = read_scene(&path, &[]).unwrap();
        assert_eq!(
            s.cloth.num_width_points * s.cloth.num_height_points,
            2500,
            "{name}"
        );
    }
}

/// A value an override sets is checked as the file's are, and its error names the
/// override, not the line of the file where the key was.
#[test]
fn override_errors_name_the_override() {
    let set = |s: &[&str]| s.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    let e = parse_scene(PINNED2, "p.json", &set(&["ks=500", "ks=-1"])).unwrap_err();
    assert_eq!(
        e.to_string(),
        "--set ks=-1: ks: expected a spring constant from 0 to 1e12, found -1"
    );
    let e = parse_scene(PINNED2, "p.json", &set(&["pinned=[[0, 0], [90, 0]]"])).unwrap_err();
    assert!(
        e.to_string()
            .starts_with("--set pinned=[[0, 0], [90, 0]]: "),
        "{e}"
    );
    // A bad value in the file itself still names its line.
    let bad = PINNED2.replace("\"ks\": 5000.0", "\"ks\": -5");
    let e = parse_scene(&bad, "p.json", &set(&["density=15"])).unwrap_err();
    assert!(e.to_string().starts_with("p.json:3: "), "{e}");
}
