//! Mitsuba 3 scene files rendered by prism against Mitsuba 3's own render of the same file.

use prism_render::film::FilmSettings;
use prism_render::integrators::PathSettings;
use prism_render::render::RenderOptions;
use prism_render::render_scene::RenderScene;

/// Oracle: Mitsuba 3 (`llvm_ad_rgb`, 3.9.1) rendering `docs/examples/cbox.xml` (the README's
/// example),
/// an open-topped Cornell box written in Mitsuba's format (rectangles, a cube and a sphere
/// placed by composed transforms, `twosided` and plain diffuse, an area emitter on a
/// rectangle, a point light, `path` with `max_depth` 6, a box filter), by
/// `scripts/mitsuba_xml_reference.py docs/examples/cbox.xml ... 256 64`: `cbox.exr` is the mean of 256 renders of 64 samples,
/// `cbox_variance.exr` one sample's luminance variance per pixel from their spread. prism
/// reads the same file and renders it at 64 samples; a per-pixel Z-test of the luminance
/// (Bonferroni over the pixels tested, significance 0.01) as for the course's Cornell box,
/// and the means per channel within 1%.
#[test]
fn a_mitsuba_scene_renders_as_mitsuba_renders_it() {
    agrees_with_mitsuba("cbox", "docs/examples/cbox.xml", &[]);
}

/// The same with Mitsuba's default reconstruction filter (`-D filter=gaussian`: a windowed
/// Gaussian of deviation 0.5, splatted with its weights), whose expected pixel values prism
/// reaches by drawing each sample's position from the filter's density (`cbox_gaussian*.exr`,
/// made by the same script with `filter=gaussian`).
#[test]
fn a_mitsuba_scene_with_the_gaussian_filter_renders_as_mitsuba_renders_it() {
    agrees_with_mitsuba(
        "cbox_gaussian",
        "docs/examples/cbox.xml",
        &[("filter", "gaussian")],
    );
}

/// Oracle: Mitsuba 3 rendering `rough.xml` (beside the references): the example box with an
/// anisotropic Beckmann copper cube (`roughconductor`, `alpha_u` 0.05, `alpha_v` 0.4, tinted
/// `specular_reflectance`) and a GGX rough water sphere (`roughdielectric`, `alpha` 0.2), made
/// by the same script; compared as the box is.
#[test]
fn rough_conductors_and_dielectrics_render_as_mitsuba_renders_them() {
    agrees_with_mitsuba(
        "rough",
        "crates/prism-render/tests/golden/mitsuba/xml/rough.xml",
        &[],
    );
}

/// Oracle: Mitsuba 3 rendering `textures.xml` (beside the references): bitmap textures
/// (bilinear and nearest; repeat and mirror; `to_uv`) on rectangles, a disk, a sphere and an
/// OBJ box read by its corners (normals computed as Mitsuba computes them), and checkerboards
/// on a rectangle and a cube; compared as the box is.
#[test]
fn textures_render_as_mitsuba_renders_them() {
    agrees_with_mitsuba(
        "textures",
        "crates/prism-render/tests/golden/mitsuba/xml/textures.xml",
        &[],
    );
}

/// Oracle: Mitsuba 3 rendering `envmap.xml` (beside the references): diffuse, rough silver
/// and glass spheres on a floor lit by an `envmap` (an OpenEXR lat-long map with a sun,
/// `scale` 1.5, turned by `to_world`), seen directly around them; compared as the box is.
#[test]
fn an_environment_map_lights_as_mitsubas_does() {
    agrees_with_mitsuba(
        "envmap",
        "crates/prism-render/tests/golden/mitsuba/xml/envmap.xml",
        &[],
    );
}

/// Oracle: Mitsuba 3 rendering `roughplastic.xml` (beside the references): the example box
/// with a GGX rough plastic cube and a Beckmann one (its coat's transmittance table and
/// internal reflectance computed as Mitsuba computes them); compared as the box is.
#[test]
fn rough_plastics_render_as_mitsuba_renders_them() {
    agrees_with_mitsuba(
        "roughplastic",
        "crates/prism-render/tests/golden/mitsuba/xml/roughplastic.xml",
        &[],
    );
}

/// Oracle: Mitsuba 3 rendering `blend.xml` (beside the references): the example box with a
/// `blendbsdf` of diffuse and rough gold by a checkerboard weight, a `twosided` blend by a
/// constant, a `mask` of constant opacity and one cut by a bitmap's luminance; compared as
/// the box is.
#[test]
fn blends_and_masks_render_as_mitsuba_renders_them() {
    agrees_with_mitsuba(
        "blend",
        "crates/prism-render/tests/golden/mitsuba/xml/blend.xml",
        &[],
    );
}

/// Oracle: Mitsuba 3 rendering `maps.xml` (beside the references): the example box with a
/// `normalmap` over rough plastic and over a `twosided` diffuse (looked up nearest), and a
/// `bumpmap` over a diffuse sphere and over rough gold (its heights repeated by `to_uv`);
/// compared as the box is.
#[test]
fn bump_and_normal_maps_render_as_mitsuba_renders_them() {
    agrees_with_mitsuba(
        "maps",
        "crates/prism-render/tests/golden/mitsuba/xml/maps.xml",
        &[],
    );
}

/// Oracle: Mitsuba 3 rendering `anisotropic.xml` (beside the references): an anisotropic
/// GGX conductor on a mesh without texture coordinates, whose tangent is each face's first
/// edge as in Mitsuba's meshes (a tangent from the normal's frame missed by 0.89 in a block
/// of 8x8 pixels); compared as the box is.
#[test]
fn anisotropy_on_a_mesh_without_uvs_runs_as_mitsubas() {
    agrees_with_mitsuba(
        "anisotropic",
        "crates/prism-render/tests/golden/mitsuba/xml/anisotropic.xml",
        &[],
    );
}

/// Oracle: Mitsuba 3 rendering `principled.xml` (beside the references): `principled` with
/// a textured base colour, metal, specular tint and clearcoat; with transmission; with
/// anisotropy, sheen and flatness; and inside `twosided`; compared as the box is.
#[test]
fn principled_bsdfs_render_as_mitsuba_renders_them() {
    agrees_with_mitsuba(
        "principled",
        "crates/prism-render/tests/golden/mitsuba/xml/principled.xml",
        &[],
    );
}

/// Oracle: Mitsuba 3 rendering `weights.xml` (beside the references): `principled` with its
/// roughness, metallic, clearcoat, transmission, anisotropy, sheen and flatness given by
/// bitmaps (raw and sRGB) and checkerboards; compared as the box is.
#[test]
fn textured_principled_weights_render_as_mitsuba_renders_them() {
    agrees_with_mitsuba(
        "weights",
        "crates/prism-render/tests/golden/mitsuba/xml/weights.xml",
        &[],
    );
}

/// Oracle: Mitsuba 3 rendering `emitters.xml` (beside the references): area emitters whose
/// radiance is a texture (an OpenEXR bitmap on a rectangle, a checkerboard on a cube),
/// seen directly and lighting the box; compared as the box is.
#[test]
fn textured_emitters_render_as_mitsuba_renders_them() {
    agrees_with_mitsuba(
        "emitters",
        "crates/prism-render/tests/golden/mitsuba/xml/emitters.xml",
        &[],
    );
}

/// Oracle: Mitsuba 3 rendering `spheres.xml` (beside the references): a textured sphere
/// and an anisotropic GGX sphere, each turned by its `to_world`, whose texture coordinates
/// and `dp/du` follow the sphere's own axes; compared as the box is.
#[test]
fn turned_spheres_render_as_mitsuba_renders_them() {
    agrees_with_mitsuba(
        "spheres",
        "crates/prism-render/tests/golden/mitsuba/xml/spheres.xml",
        &[],
    );
}

/// Oracle: Mitsuba 3 rendering `parameters.xml` (beside the references): textures as a
/// rough conductor's alpha, a glass's specular_transmittance, a plastic's
/// specular_reflectance and a rough dielectric's alpha_u alone (anisotropic, a checkerboard
/// read as a number); compared as the box is.
#[test]
fn textured_parameters_render_as_mitsuba_renders_them() {
    agrees_with_mitsuba(
        "parameters",
        "crates/prism-render/tests/golden/mitsuba/xml/parameters.xml",
        &[],
    );
}

/// prism's render of `scene` (from the workspace's root) with `defines` against the
/// reference `NAME.exr` and its variance `NAME_variance.exr`.
fn agrees_with_mitsuba(name: &str, scene: &str, defines: &[(&str, &str)]) {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden/mitsuba/xml");
    let reference =
        prism_image::read_exr(&dir.join(format!("{name}.exr"))).expect("the reference reads");
    let variance = prism_image::read_exr(&dir.join(format!("{name}_variance.exr")))
        .expect("the variance reads");
    let file = prism_testkit::workspace_root().join(scene);
    let defines: Vec<(String, String)> = defines
        .iter()
        .map(|(a, b)| (a.to_string(), b.to_string()))
        .collect();
    let m = prism_scene::read_mitsuba(&file, &defines).expect("the scene reads");
    assert_eq!(m.settings.size, (reference.width(), reference.height()));
    assert_eq!(m.settings.spp, 64);
    assert_eq!(m.settings.max_bounces, Some(5));
    let scene = RenderScene::new(&m.scene);
    let opts = RenderOptions::mitsuba(&m.settings, RenderOptions::default());
    let sums = whole_render(&scene, &opts);
    // Near a directly seen emitter a wide filter's tail reaches radiance far above the
    // pixel's own: drawing positions from the filter finds it rarely (unbiased, but with a
    // variance 64 samples do not estimate), while splatting weighs it in every sample. Those
    // pixels are compared in their sum; the rest one by one.
    let (w, h) = (reference.width() as i64, reference.height() as i64);
    let reach = if m.settings.filter == prism_scene::Filter::Box {
        0
    } else {
        2
    };
    let near_emitter = |i: usize| {
        let (x, y) = (i as i64 % w, i as i64 / w);
        (-reach..=reach).any(|dy| {
            (-reach..=reach).any(|dx| {
                let (u, v) = (x + dx, y + dy);
                (0..w).contains(&u)
                    && (0..h).contains(&v)
                    && reference.get(u as u32, v as u32).luminance() > 1.0
            })
        })
    };
    let (mut near_ours, mut near_theirs) = (0f64, 0f64);
    let (mut ours, mut theirs) = (Vec::new(), Vec::new());
    let mut mean_ours = [0f64; 3];
    let mut mean_theirs = [0f64; 3];
    let references = sums.pixels().iter().zip(reference.pixels());
    for (i, ((p, r), v)) in references.zip(variance.pixels()).enumerate() {
        let n = f64::from(p.n);
        let mean = p.moment1 / n;
        let own = ((p.moment2 - p.moment1 * mean) / (n - 1.0)).max(0.0);
        let reference_var = f64::from(v.r);
        ours.push(prism_testkit::Estimate {
            mean,
            variance: own.max(reference_var) / n,
        });
        theirs.push(prism_testkit::Estimate {
            mean: f64::from(r.luminance()),
            variance: reference_var / (256.0 * 64.0),
        });
        if reach > 0 && near_emitter(i) {
            near_ours += ours.pop().map_or(0.0, |e| e.mean);
            near_theirs += theirs.pop().map_or(0.0, |e| e.mean);
        }
        let c = p.mean();
        for (acc, x) in mean_ours.iter_mut().zip([c.r, c.g, c.b]) {
            *acc += f64::from(x);
        }
        for (acc, x) in mean_theirs.iter_mut().zip([r.r, r.g, r.b]) {
            *acc += f64::from(x);
        }
    }
    for c in 0..3 {
        let ratio = mean_ours[c] / mean_theirs[c];
        assert!(
            (ratio - 1.0).abs() < 0.01,
            "channel {c}: prism / Mitsuba = {ratio}"
        );
    }
    if reach > 0 {
        let ratio = near_ours / near_theirs;
        assert!(
            (ratio - 1.0).abs() < 0.02,
            "{name}: near the emitter, prism / Mitsuba = {ratio}"
        );
    }
    let z = prism_testkit::z_test(&ours, &theirs, 0.01, 1e-3);
    // (With pixels near an emitter left out, the worst index counts only those kept.)
    let width = reference.width() as usize;
    let (x, y) = (z.worst_pixel % width, z.worst_pixel / width);
    assert!(
        z.passed(),
        "{name}: {z:?}: pixel ({x}, {y}) prism {:?} vs Mitsuba {:?}",
        ours[z.worst_pixel],
        theirs[z.worst_pixel]
    );
    assert!(z.tested > 8_000, "{name}: {} pixels vary", z.tested);
}

/// Closed form: a diffuse rectangle of albedo 0.5 alone under a constant emitter of radiance
/// 1 reflects exactly 0.5 towards any viewer it faces (it sees nothing but the emitter).
/// Seen from behind, Mitsuba's `diffuse` is black, `twosided` diffuse reflects 0.5 again,
/// and a sphere with `flip_normals` is black from outside.
#[test]
fn opaque_bsdfs_are_black_from_behind_unless_twosided() {
    let dir = tempfile_dir("one-sided");
    let center_pixel = |shape: &str, camera_z: f32| -> f32 {
        let xml = format!(
            r#"<scene version="3.0.0">
    <integrator type="path"><integer name="max_depth" value="8"/></integrator>
    <sensor type="perspective">
        <float name="fov" value="20"/>
        <transform name="to_world"><lookat origin="0, 0, {camera_z}" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/><rfilter type="box"/></film>
    </sensor>
    <emitter type="constant"/>
    {shape}
</scene>"#
        );
        let file = dir.join("s.xml");
        std::fs::write(&file, xml).unwrap();
        let m = prism_scene::read_mitsuba(&file, &[]).expect("the scene reads");
        let scene = RenderScene::new(&m.scene);
        let opts = RenderOptions {
            film: FilmSettings {
                width: 8,
                height: 8,
                spp: 64,
                ..FilmSettings::default()
            },
            path: PathSettings::default(),
        };
        let sums = whole_render(&scene, &opts);
        sums.pixels()[4 * 8 + 4].mean().g
    };
    let diffuse = r#"<shape type="rectangle"><bsdf type="diffuse"/></shape>"#;
    let twosided =
        r#"<shape type="rectangle"><bsdf type="twosided"><bsdf type="diffuse"/></bsdf></shape>"#;
    let inward = r#"<shape type="sphere"><float name="radius" value="0.5"/><boolean name="flip_normals" value="true"/></shape>"#;
    let front = center_pixel(diffuse, 5.0);
    assert!((front - 0.5).abs() < 0.02, "{front}");
    assert_eq!(center_pixel(diffuse, -5.0), 0.0);
    let back = center_pixel(twosided, -5.0);
    assert!((back - 0.5).abs() < 0.02, "{back}");
    assert_eq!(center_pixel(inward, 5.0), 0.0);
}

/// The pixel sums of a whole render of `scene` with `opts` (every tile, every sample).
fn whole_render(
    scene: &RenderScene,
    opts: &RenderOptions,
) -> prism_image::Image<prism_render::film::PixelSum> {
    let share = prism_render::film::Share::whole(opts.film.spp);
    let job = prism_render::render::Job::share(&share);
    prism_render::render::render_share(scene, opts, &job, &|_| {})
}

/// A fresh folder for a test's files.
fn tempfile_dir(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("prism-mitsuba-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Oracle: brute force. A diffuse square tilted 60 degrees just under a one-sided area light,
/// which most of its points see at a grazing angle: direct light by light sampling equals
/// direct light by uniform hemisphere sampling (which aims no ray at the light). A shadow ray
/// aimed along the sampled direction from the pushed-off origin met the light before the
/// point sampled, and lost a fifth of the light.
#[test]
fn light_sampling_equals_hemisphere_sampling_under_a_grazing_light() {
    let dir = tempfile_dir("grazing");
    let file = dir.join("s.xml");
    std::fs::write(
        &file,
        r#"<scene version="3.0.0">
    <sensor type="perspective">
        <float name="fov" value="40"/>
        <transform name="to_world"><lookat origin="0.25, 2.46, 1.2" target="0.25, 1.66, -0.16" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="16"/><rfilter type="box"/></film>
    </sensor>
    <shape type="rectangle">
        <transform name="to_world"><scale x="0.25" y="0.25"/><rotate x="1" angle="90"/><translate y="1.95"/></transform>
        <emitter type="area"><rgb name="radiance" value="10"/></emitter>
    </shape>
    <shape type="rectangle">
        <transform name="to_world"><scale value="0.3"/><rotate x="1" angle="-60"/><translate x="0.25" y="1.66" z="-0.16"/></transform>
        <bsdf type="diffuse"/>
    </shape>
</scene>"#,
    )
    .unwrap();
    let m = prism_scene::read_mitsuba(&file, &[]).expect("the scene reads");
    let scene = RenderScene::new(&m.scene);
    let total = |hemisphere: bool, spp: u32| -> f64 {
        let opts = RenderOptions {
            film: FilmSettings {
                width: 16,
                height: 16,
                spp,
                ..FilmSettings::default()
            },
            path: PathSettings {
                max_bounces: 1,
                integrator: prism_render::integrators::Integrator::Direct { hemisphere },
                ..PathSettings::default()
            },
        };
        let sums = whole_render(&scene, &opts);
        sums.pixels().iter().map(|p| f64::from(p.mean().g)).sum()
    };
    let (lights, brute) = (total(false, 512), total(true, 2048));
    assert!(
        (lights / brute - 1.0).abs() < 0.02,
        "light sampling {lights} vs hemisphere {brute}"
    );
}

/// Closed form: with `hide_emitters`, the constant emitter seen straight from the camera
/// is black while a diffuse plate of albedo 0.5 it lights still shows 0.5; and Mitsuba's
/// `direct` integrator is read as one bounce.
#[test]
fn hidden_emitters_are_black_to_the_camera_only() {
    let dir = tempfile_dir("hide");
    let file = dir.join("s.xml");
    std::fs::write(
        &file,
        r#"<scene version="3.0.0">
    <integrator type="direct"><boolean name="hide_emitters" value="true"/></integrator>
    <sensor type="perspective">
        <float name="fov" value="40"/>
        <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/><rfilter type="box"/></film>
    </sensor>
    <emitter type="constant"/>
    <shape type="rectangle"><transform name="to_world"><scale x="0.8" y="4"/></transform><bsdf type="diffuse"/></shape>
</scene>"#,
    )
    .unwrap();
    let m = prism_scene::read_mitsuba(&file, &[]).expect("the scene reads");
    assert!(m.settings.hide_emitters);
    assert_eq!(m.settings.max_bounces, Some(1));
    let scene = RenderScene::new(&m.scene);
    let opts = RenderOptions {
        film: FilmSettings {
            width: 8,
            height: 8,
            spp: 256,
            ..FilmSettings::default()
        },
        path: PathSettings {
            max_bounces: 1,
            hide_emitters: true,
            ..PathSettings::default()
        },
    };
    let sums = whole_render(&scene, &opts);
    let plate = sums.pixels()[4 * 8 + 4].mean().g;
    assert!((plate - 0.5).abs() < 0.02, "{plate}");
    assert_eq!(sums.pixels()[0].mean(), prism_math::Rgb::BLACK);
}

/// Closed form: in front of a constant emitter of radiance 1, a plate that fills the view
/// and is a `mask` of opacity 0.3 over black passes 0.7 of the light, and the pass counts
/// as a bounce as in Mitsuba's path integrator (`max_depth` 1 sees nothing through it);
/// a plate that blends white and black diffuse by weight 0.3 under the same light shows
/// 0.7.
#[test]
fn masks_pass_and_blends_mix_in_expectation() {
    let mean = |name: &str, bsdf: &str, max_bounces: u32| -> f32 {
        let dir = tempfile_dir(name);
        let file = dir.join("s.xml");
        std::fs::write(
            &file,
            format!(
                r#"<scene version="3.0.0">
    <sensor type="perspective">
        <float name="fov" value="40"/>
        <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/><rfilter type="box"/></film>
    </sensor>
    <emitter type="constant"/>
    <shape type="rectangle"><transform name="to_world"><scale value="4"/></transform>{bsdf}</shape>
</scene>"#
            ),
        )
        .unwrap();
        mean_green(&file, 8, 512, max_bounces)
    };
    let mask = r#"<bsdf type="mask"><float name="opacity" value="0.3"/><bsdf type="diffuse"><rgb name="reflectance" value="0"/></bsdf></bsdf>"#;
    assert_eq!(mean("mask0", mask, 0), 0.0);
    let through = mean("mask1", mask, 1);
    assert!((through - 0.7).abs() < 0.01, "{through}");
    let blend = r#"<bsdf type="blendbsdf"><float name="weight" value="0.3"/><bsdf type="diffuse"><rgb name="reflectance" value="1"/></bsdf><bsdf type="diffuse"><rgb name="reflectance" value="0"/></bsdf></bsdf>"#;
    let mixed = mean("blend", blend, 1);
    assert!((mixed - 0.7).abs() < 0.01, "{mixed}");
}

/// Closed form: a white diffuse plate facing +z under a normal map of one normal, tilted
/// 30 degrees towards +x, lit by a directional light of irradiance 2 arriving 45 degrees
/// from +z on the +x side and seen head-on, shows `2 cos 15 / pi` times Mitsuba's shadowing
/// term `2 / (1 + sqrt(1 + a tan^2 45))`, `a = tan^2 30 / 8`; the term off, `2 cos 15 / pi`;
/// light from the -x side past the tilted normal's horizon (80 degrees), nothing.
#[test]
fn a_normal_map_tilts_the_shading_normal_as_mitsubas_does() {
    let render = |name: &str, shadowing: bool, light_deg: f32| -> f32 {
        let dir = tempfile_dir(name);
        let n = prism_math::Vec3::new(30f32.to_radians().sin(), 0.0, 30f32.to_radians().cos());
        let texel = prism_math::Rgb::new((n.x + 1.0) / 2.0, (n.y + 1.0) / 2.0, (n.z + 1.0) / 2.0);
        prism_image::write_exr(&dir.join("n.exr"), &prism_image::RgbImage::new(1, 1, texel))
            .unwrap();
        let (s, c) = light_deg.to_radians().sin_cos();
        let file = dir.join("s.xml");
        std::fs::write(
            &file,
            format!(
                r#"<scene version="3.0.0">
    <integrator type="path"><integer name="max_depth" value="2"/></integrator>
    <sensor type="perspective">
        <float name="fov" value="5"/>
        <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="4"/><integer name="height" value="4"/><rfilter type="box"/></film>
    </sensor>
    <emitter type="directional"><vector name="direction" x="{}" y="0" z="{}"/><rgb name="irradiance" value="2"/></emitter>
    <shape type="rectangle">
        <bsdf type="normalmap">
            <boolean name="use_shadowing_function" value="{shadowing}"/>
            <texture type="bitmap" name="normalmap"><string name="filename" value="n.exr"/></texture>
            <bsdf type="diffuse"><rgb name="reflectance" value="1"/></bsdf>
        </bsdf>
    </shape>
</scene>"#,
                -s, -c
            ),
        )
        .unwrap();
        mean_green(&file, 4, 4, 1)
    };
    let lit = 2.0 * 15f32.to_radians().cos() / std::f32::consts::PI;
    let a = 30f32.to_radians().tan().powi(2) / 8.0;
    let term = 2.0 / (1.0 + (1.0 + a * 45f32.to_radians().tan().powi(2)).sqrt());
    let with = render("tilt-on", true, 45.0);
    assert!(
        (with - lit * term).abs() < 1e-4 * lit,
        "{with} vs {}",
        lit * term
    );
    let without = render("tilt-off", false, 45.0);
    assert!((without - lit).abs() < 1e-4 * lit, "{without} vs {lit}");
    assert_eq!(render("tilt-behind", true, -80.0), 0.0);
}

/// Oracle: Mitsuba's own RGBE writer. `sky.hdr` is Mitsuba 3's `Bitmap.write` of `sky.exr`
/// (run-length encoded): each pixel reads back within the 8-bit mantissa's rounding of the
/// OpenEXR's (1/128 of its largest channel).
#[test]
fn a_radiance_file_written_by_mitsuba_reads_as_its_source() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden/mitsuba/xml");
    let exr = prism_image::read_exr(&dir.join("sky.exr")).unwrap();
    let bytes = std::fs::read(dir.join("sky.hdr")).unwrap();
    let hdr = prism_image::decode_hdr(&bytes, "sky.hdr").unwrap();
    assert_eq!((hdr.width(), hdr.height()), (exr.width(), exr.height()));
    for (a, b) in hdr.pixels().iter().zip(exr.pixels()) {
        let tolerance = b.max_channel() / 128.0;
        for (x, y) in [(a.r, b.r), (a.g, b.g), (a.b, b.b)] {
            assert!((x - y).abs() <= tolerance, "{a:?} vs {b:?}");
        }
    }
}

/// Closed form: an area emitter keeps its shape's BSDF, whatever it is. A plate that emits
/// 0.25 and is a perfect mirror (Mitsuba's default conductor), seen head-on under a constant
/// emitter of 1, shows 1.25; a textured diffuse emitter is lit and textured as well (0.25
/// plus its albedo 0.6 times 1).
#[test]
fn area_emitters_keep_their_surfaces_bsdf() {
    let mean = |name: &str, bsdf: &str| -> f32 {
        let dir = tempfile_dir(name);
        prism_image::write_exr(
            &dir.join("albedo.exr"),
            &prism_image::RgbImage::new(2, 2, prism_math::Rgb::splat(0.6)),
        )
        .unwrap();
        let file = dir.join("s.xml");
        std::fs::write(
            &file,
            format!(
                r#"<scene version="3.0.0">
    <sensor type="perspective">
        <float name="fov" value="10"/>
        <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/><rfilter type="box"/></film>
    </sensor>
    <emitter type="constant"/>
    <shape type="rectangle">
        <emitter type="area"><rgb name="radiance" value="0.25"/></emitter>
        {bsdf}
    </shape>
</scene>"#
            ),
        )
        .unwrap();
        mean_green(&file, 8, 256, 1)
    };
    let mirror = mean("emitter-mirror", r#"<bsdf type="conductor"/>"#);
    assert!((mirror - 1.25).abs() < 1e-4, "{mirror}");
    let textured = mean(
        "emitter-textured",
        r#"<bsdf type="diffuse"><texture type="bitmap" name="reflectance"><string name="filename" value="albedo.exr"/></texture></bsdf>"#,
    );
    assert!((textured - 0.85).abs() < 0.01, "{textured}");
}

/// Closed form: a film's crop window sees what the whole film sees there. For a
/// perspective, a thin-lens and an orthographic sensor, the ray through position `(x, y)`
/// of a 30x20 crop at (50, 10) of a 128x96 film is the whole film's ray through
/// `(x + 50, y + 10)`; the image is the crop's size. (Mitsuba renders the same crop of
/// docs/examples/cbox.xml with means within 0.005%.)
#[test]
fn a_film_crop_is_a_window_of_the_whole_films_view() {
    for sensor in [
        r#"<sensor type="perspective"><float name="fov" value="50"/>"#,
        r#"<sensor type="thinlens"><float name="fov" value="50"/><float name="aperture_radius" value="0.2"/><float name="focus_distance" value="4"/>"#,
        r#"<sensor type="orthographic">"#,
    ] {
        let read = |crop: &str| {
            let dir = tempfile_dir("crop");
            let file = dir.join("s.xml");
            std::fs::write(
                &file,
                format!(
                    r#"<scene version="3.0.0">
    {sensor}
        <transform name="to_world"><lookat origin="1, 2, 5" target="0, 0.5, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="128"/><integer name="height" value="96"/>{crop}</film>
    </sensor>
</scene>"#
                ),
            )
            .unwrap();
            prism_scene::read_mitsuba(&file, &[]).expect("the scene reads")
        };
        let whole = read("");
        let cropped = read(
            r#"<integer name="crop_offset_x" value="50"/><integer name="crop_offset_y" value="10"/><integer name="crop_width" value="30"/><integer name="crop_height" value="20"/>"#,
        );
        assert_eq!(cropped.settings.size, (30, 20));
        assert_eq!(whole.settings.size, (128, 96));
        let full = prism_render::camera::Perspective::new(&whole.scene.camera, 128, 96);
        let part = prism_render::camera::Perspective::new(&cropped.scene.camera, 30, 20);
        for (x, y) in [(0.0, 0.0), (12.3, 7.9), (30.0, 20.0), (29.5, 0.5)] {
            let lens = prism_math::Vec2::new(0.3, 0.7);
            let (a, b) = (part.ray(x, y, lens), full.ray(x + 50.0, y + 10.0, lens));
            assert!(
                (a.origin - b.origin).length() < 1e-5 && (a.dir - b.dir).length() < 1e-5,
                "{sensor} at {x}, {y}: {a:?} vs {b:?}"
            );
        }
    }
}

/// The mean green of prism's render of the Mitsuba scene `file` at `size` x `size` pixels,
/// `spp` samples and at most `max_bounces` bounces.
fn mean_green(file: &std::path::Path, size: u32, spp: u32, max_bounces: u32) -> f32 {
    let m = prism_scene::read_mitsuba(file, &[]).expect("the scene reads");
    let scene = RenderScene::new(&m.scene);
    let opts = RenderOptions {
        film: FilmSettings {
            width: size,
            height: size,
            spp,
            ..FilmSettings::default()
        },
        path: PathSettings {
            max_bounces,
            ..PathSettings::default()
        },
    };
    let sums = whole_render(&scene, &opts);
    sums.pixels().iter().map(|p| p.mean().g).sum::<f32>() / (size * size) as f32
}

/// Closed form: a white diffuse plate (albedo 0.5) facing the camera, under a constant
/// emitter of radiance 0.2 (behind the camera, seen by the plate's upper hemisphere only)
/// and two directional lights of irradiance 2 (head-on) and 3 (at 60 degrees), one bounce:
/// `0.5 * 0.2 + 0.5 / pi * (2 + 3 cos 60)`. With one light picked per light sample (the
/// options Mitsuba scenes render with) as with every light sampled.
#[test]
fn one_light_per_sample_keeps_the_expectation() {
    let dir = tempfile_dir("one-light");
    let file = dir.join("s.xml");
    std::fs::write(
        &file,
        r#"<scene version="3.0.0">
    <integrator type="path"><integer name="max_depth" value="2"/></integrator>
    <sensor type="perspective">
        <float name="fov" value="20"/>
        <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
        <sampler type="independent"><integer name="sample_count" value="512"/></sampler>
        <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/><rfilter type="box"/></film>
    </sensor>
    <emitter type="constant"><rgb name="radiance" value="0.2"/></emitter>
    <emitter type="directional"><vector name="direction" value="0, 0, -1"/><rgb name="irradiance" value="2"/></emitter>
    <emitter type="directional"><vector name="direction" value="0, -0.8660254, -0.5"/><rgb name="irradiance" value="3"/></emitter>
    <shape type="rectangle"><transform name="to_world"><scale value="4"/></transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf></shape>
</scene>"#,
    )
    .unwrap();
    let m = prism_scene::read_mitsuba(&file, &[]).expect("the scene reads");
    let scene = RenderScene::new(&m.scene);
    let expected = 0.5 * 0.2 + 0.5 / std::f32::consts::PI * (2.0 + 3.0 * 0.5);
    let picked = RenderOptions::mitsuba(&m.settings, RenderOptions::default());
    assert!(picked.path.one_light);
    let every = RenderOptions {
        path: PathSettings {
            one_light: false,
            ..picked.path
        },
        ..picked
    };
    for (what, opts) in [("one light", picked), ("every light", every)] {
        let sums = whole_render(&scene, &opts);
        let mean = sums.pixels().iter().map(|p| p.mean().g).sum::<f32>() / 64.0;
        assert!(
            (mean / expected - 1.0).abs() < 0.01,
            "{what}: {mean} against {expected}"
        );
    }
}

/// Closed form, as Mitsuba 3.9.1's path integrator defines `hide_emitters`: camera rays pass
/// through area emitters (not only their light is hidden). A plate of albedo 0.5 under a
/// constant emitter of radiance 1 shows 0.5 through an emitting square in front of it, and
/// the square, facing the camera, sheds no light on the plate (and, small and near the
/// camera, hides 0.08% of its sky).
#[test]
fn hidden_emitters_let_camera_rays_through() {
    let dir = tempfile_dir("hidden-through");
    let file = dir.join("s.xml");
    std::fs::write(
        &file,
        r#"<scene version="3.0.0">
    <integrator type="direct"><boolean name="hide_emitters" value="true"/></integrator>
    <sensor type="perspective">
        <float name="fov" value="40"/>
        <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/><rfilter type="box"/></film>
    </sensor>
    <emitter type="constant"/>
    <shape type="rectangle"><transform name="to_world"><scale value="4"/></transform><bsdf type="diffuse"/></shape>
    <shape type="rectangle">
        <transform name="to_world"><scale value="0.1"/><translate z="4"/></transform>
        <emitter type="area"><rgb name="radiance" value="50"/></emitter>
    </shape>
</scene>"#,
    )
    .unwrap();
    let m = prism_scene::read_mitsuba(&file, &[]).expect("the scene reads");
    let scene = RenderScene::new(&m.scene);
    for integrator in [
        prism_render::integrators::Integrator::Path,
        prism_render::integrators::Integrator::PathScalar,
    ] {
        let base = RenderOptions::mitsuba(&m.settings, RenderOptions::default());
        let opts = RenderOptions {
            film: FilmSettings {
                spp: 256,
                ..base.film
            },
            path: PathSettings {
                integrator,
                ..base.path
            },
        };
        let sums = whole_render(&scene, &opts);
        let centre = sums.pixels()[4 * 8 + 4].mean().g;
        assert!((centre - 0.5).abs() < 0.02, "{integrator:?}: {centre}");
    }
}
