//! Tests of the render-config reader: values as written, defaults as documented, and a
//! located error for every kind of bad input.

use super::*;

fn parse(text: &str) -> Result<RenderConfig, SceneError> {
    parse_render_config(text, "c.toml", Path::new("/cfg"))
}

/// Closed form: every key reads back as written; ints stand for floats; paths are
/// relative to the config's folder.
#[test]
fn every_key_reads_back() {
    let c = parse(
        r#"
command_line_rendering = true
window_size = [320, 240]
data_path = "../data"
scene = "cornell_box_parallelogram_light"
output_dir = "out"
[features]
enable_shading = true
enable_hard_shadow = true
[features.extra]
enable_bloom_effect = true
enable_bilinear_texture_filtering = true
[[cameras]]
field_of_view = 60
distance_from_look_at = 2.5
look_at = [0, 0.5, 0]
rotation = [10, -30.0, 0]
[[cameras]]
[[lights]]
type = "point"
position = [1, 2, 3]
color = [1, 1, 1]
[[lights]]
type = "segment"
endpoints = [[0, 0, 0], [1, 0, 0]]
colors = [[1, 0, 0], [0, 1, 0]]
[[lights]]
type = "parallelogram"
corner = [0, 1, 0]
edges = [[1, 0, 0], [0, 0, 1]]
colors = [[1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1]]
"#,
    )
    .unwrap();
    assert_eq!(c.window_size, Some([320, 240]));
    assert_eq!(c.data_path, Some(PathBuf::from("/cfg/../data")));
    assert_eq!(c.output_dir, Some(PathBuf::from("/cfg/out")));
    assert_eq!(
        c.scene,
        SceneSource::Preset(Preset::CornellBoxParallelogramLight)
    );
    assert!(
        c.features.shading && c.features.hard_shadow && c.features.bloom && c.features.bilinear
    );
    assert!(!c.features.recursive && !c.features.accel_structure);
    assert_eq!(c.cameras.len(), 2);
    assert_eq!(c.cameras[0].fov_y, 60.0);
    assert_eq!(c.cameras[0].rotation, Vec3::new(10.0, -30.0, 0.0));
    assert_eq!(c.cameras[1], OrbitCamera::default());
    assert_eq!(c.lights.len(), 3);
    assert!(matches!(c.lights[2], Light::Parallelogram { .. }));
}

/// Defaults: the single triangle, every feature off, no cameras (the default camera is
/// the renderer's), `"default"` data path means none.
#[test]
fn defaults() {
    let c = parse("data_path = \"default\"\nscene = 3\n").unwrap();
    assert_eq!(c.data_path, None);
    assert_eq!(c.scene, SceneSource::Preset(Preset::CornellBox));
    assert_eq!(c.features, Features::default());
    let c = parse("").unwrap();
    assert_eq!(c.scene, SceneSource::Preset(Preset::SingleTriangle));
    let c = parse("scene = \"my/model.OBJ\"").unwrap();
    assert_eq!(c.scene, SceneSource::File(PathBuf::from("my/model.OBJ")));
}

/// Every kind of bad input names the line and what was expected.
#[test]
fn bad_configs_are_located() {
    let cases = [
        ("scene = \"kitchen\"", "c.toml:1: scene: expected a preset"),
        (
            "scene = 12",
            "c.toml:1: scene: expected a preset number from 0 to 9, found 12",
        ),
        (
            "\n[[cameras]]\nfield_of_view = 0",
            "c.toml:3: field_of_view: expected degrees strictly between 0 and 180, found 0",
        ),
        (
            "[[cameras]]\nfield_of_view = \"wide\"",
            "c.toml:2: field_of_view: expected a number, found string",
        ),
        (
            "window_size = [0, 10]",
            "c.toml:1: window_size: expected sides from 1 to 16384, found 0",
        ),
        (
            "window_size = [16000, 16000]",
            "c.toml:1: window_size: 16000 x 16000 is over the limit",
        ),
        (
            "window_size = [10]",
            "c.toml:1: window_size: expected 2 elements, found 1",
        ),
        (
            "[[lights]]\ntype = \"parallelogram\"\ncorner = [0,0,0]\nedges = [[1,0,0],[2,0,0]]\n\
             colors = [[1,1,1],[1,1,1],[1,1,1],[1,1,1]]",
            "c.toml:4: edges: a parallelogram light needs an area above 0",
        ),
        (
            "[[lights]]\ntype = \"segment\"\nendpoints = [[1,0,0],[1,0,0]]\ncolors = [[1,1,1],[1,1,1]]",
            "c.toml:3: endpoints: a segment light needs two different ends",
        ),
        (
            "[[lights]]\ntype = \"spot\"",
            "c.toml:2: type: expected \"point\", \"segment\" or \"parallelogram\", found \"spot\"",
        ),
        (
            "[[lights]]\ntype = \"point\"\nposition = [0,0,0]",
            "c.toml:1: point light: missing required key \"color\"",
        ),
        (
            "[[lights]]\ntype = \"point\"\nposition = [0,0,0]\ncolor = [1,-1,1]",
            "c.toml:4: color: expected colour values from 0 to 1000000",
        ),
        (
            "[features]\nenable_shadin = true",
            "c.toml:2: unknown key \"enable_shadin\" in [features]",
        ),
        (
            "[features]\nenable_shading = 1",
            "c.toml:2: enable_shading: expected true or false, found integer",
        ),
        ("scene = \"cube", "c.toml:1: expected TOML"),
        (
            "[[cameras]]\nlook_at = [0, nan, 0]",
            "c.toml:2: look_at: expected a finite number",
        ),
        (
            "colour = 1",
            "c.toml:1: unknown key \"colour\" in the top level",
        ),
    ];
    for (text, want) in cases {
        let e = parse(text).unwrap_err().to_string();
        assert!(e.starts_with(want), "{text:?}\n got: {e}\nwant: {want}");
    }
}

/// Closed form: every extra's switch and setting reads back as written, the rest keep the
/// documented defaults; `[[motion]]` at the top level and `motion` in `[extras]` both count.
#[test]
fn extras_read_back() {
    let c = parse(
        r#"
[features.extra]
enable_motion_blur = true
enable_depth_of_field = true
enable_glossy_reflection = true
enable_environment_mapping = true
enable_mipmap_texture_filtering = true
enable_bvh_sah_binning = true
[[motion]]
mesh = "tallBox"
velocity = [0.1, 0, 0]
[extras]
dof_aperture = 0.2
dof_focal_distance = 4
glossy_samples = 9
environment_map = "sky.exr"
environment_strength = 2.5
motion = [{ mesh = 3, velocity = [0, 1, 0] }]
"#,
    )
    .unwrap();
    let f = c.features;
    assert!(f.motion_blur && f.depth_of_field && f.glossy_reflection);
    assert!(f.environment_mapping && f.mipmap && f.sah_binning);
    assert!(c.warnings.is_empty(), "{:?}", c.warnings);
    let e = &c.extras;
    assert_eq!(e.extras.dof_aperture, 0.2);
    assert_eq!(e.extras.dof_focal_distance, Some(4.0));
    assert_eq!(e.extras.glossy_samples, 9);
    assert_eq!(e.extras.dof_samples, 16);
    assert_eq!(e.extras.motion_samples, 16);
    assert_eq!(e.extras.environment_strength, 2.5);
    assert_eq!(
        e.environment_map.as_ref().map(|m| m.path.clone()),
        Some(PathBuf::from("/cfg/sky.exr"))
    );
    let motion: Vec<_> = e
        .motion
        .iter()
        .map(|m| (m.mesh.clone(), m.velocity, m.at.line))
        .collect();
    assert_eq!(
        motion,
        vec![
            (MeshRef::Name("tallBox".into()), Vec3::new(0.1, 0.0, 0.0), 9),
            (MeshRef::Index(3), Vec3::new(0.0, 1.0, 0.0), 18),
        ]
    );
    let d = parse("").unwrap();
    assert_eq!(d.extras, ExtrasTable::default());
    assert_eq!(d.extras.extras.dof_aperture, 0.05);
}

/// Bad extras settings are errors naming the line, the key and what was expected.
#[test]
fn bad_extras_are_located() {
    let cases = [
        (
            "[extras]\ndof_aperture = -0.1\n",
            "c.toml:2: dof_aperture: expected a number from 0",
        ),
        (
            "[extras]\ndof_focal_distance = 0\n",
            "c.toml:2: dof_focal_distance: expected a number above 0",
        ),
        (
            "[extras]\ndof_samples = 0\n",
            "c.toml:2: dof_samples: expected 1 to 4096",
        ),
        (
            "[extras]\nglossy_samples = 100000000\n",
            "c.toml:2: glossy_samples: expected 1 to 4096",
        ),
        (
            "[extras]\nmotion_samples = 1.5\n",
            "c.toml:2: motion_samples: expected an integer",
        ),
        (
            "[extras]\nenvironment_strength = inf\n",
            "c.toml:2: environment_strength: expected a finite number",
        ),
        (
            "[extras]\nenvironment_map = 3\n",
            "c.toml:2: environment_map: expected a string",
        ),
        (
            "[extras]\nlens = 1\n",
            "c.toml:2: unknown key \"lens\" in [extras]",
        ),
        (
            "\n[[motion]]\nmesh = 0\nvelocity = [nan, 0, 0]\n",
            "c.toml:4: velocity: expected a finite number",
        ),
        (
            "[[motion]]\nvelocity = [1, 0, 0]\n",
            "c.toml:1: [[motion]]: missing required key \"mesh\"",
        ),
        (
            "[[motion]]\nmesh = -1\nvelocity = [1, 0, 0]\n",
            "c.toml:2: mesh: expected an index of 0 or more",
        ),
        (
            "[[motion]]\nmesh = 0\nvelocity = [1e9, 0, 0]\n",
            "c.toml:3: velocity: expected components up to",
        ),
        (
            "[[motion]]\nmesh = [0]\nvelocity = [1, 0, 0]\n",
            "c.toml:2: mesh: expected a mesh's name or index",
        ),
    ];
    for (text, want) in cases {
        let e = parse(text).unwrap_err().to_string();
        assert!(e.starts_with(want), "{text:?}\n got: {e}\nwant: {want}");
    }
}

/// Deep nesting is refused by the parser's recursion limit, never a stack overflow.
#[test]
fn deep_nesting_is_an_error() {
    let text = format!("x = {}{}", "[".repeat(100_000), "]".repeat(100_000));
    assert!(parse(&text).is_err());
}

/// Bounded: a config over [`MAX_CONFIG_BYTES`] is refused before its TOML is parsed (a
/// document takes about fifty times its text in memory), whether read or given as text.
#[test]
fn oversized_configs_are_refused_before_parsing() {
    let mut text = "[[motion]]\nmesh = 0\nvelocity = [1, 0, 0]\n".repeat(110_000);
    assert!(text.len() as u64 > MAX_CONFIG_BYTES);
    let e = parse(&text).unwrap_err();
    assert!(matches!(e, SceneError::TooLarge { .. }), "{e}");
    let dir = std::env::temp_dir().join(format!("prism-config-size-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("big.toml");
    std::fs::write(&file, &text).unwrap();
    let e = read_render_config(&file).unwrap_err();
    assert!(e.to_string().contains("over the limit of 4 MiB"), "{e}");
    // Just under the limit, it reads.
    text.truncate(MAX_CONFIG_BYTES as usize - MAX_CONFIG_BYTES as usize % 41);
    assert!(parse(&text).is_ok());
    std::fs::remove_dir_all(&dir).unwrap();
}
