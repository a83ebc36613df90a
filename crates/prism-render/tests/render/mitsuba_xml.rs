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
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden/mitsuba/xml");
    let reference = prism_image::read_exr(&dir.join("cbox.exr")).expect("the reference reads");
    let variance =
        prism_image::read_exr(&dir.join("cbox_variance.exr")).expect("the variance reads");
    let file = prism_testkit::workspace_root().join("docs/examples/cbox.xml");
    let m = prism_scene::read_mitsuba(&file, &[]).expect("the scene reads");
    assert_eq!(m.settings.size, (reference.width(), reference.height()));
    assert_eq!(m.settings.spp, 64);
    assert_eq!(m.settings.max_bounces, Some(5));
    let scene = RenderScene::new(&m.scene);
    let opts = RenderOptions {
        film: FilmSettings {
            width: m.settings.size.0,
            height: m.settings.size.1,
            spp: m.settings.spp,
            ..FilmSettings::default()
        },
        path: PathSettings {
            max_bounces: m.settings.max_bounces.unwrap_or(1024),
            rr_bounces: m.settings.rr_bounces,
            ..PathSettings::default()
        },
    };
    let share = prism_render::film::Share::whole(opts.film.spp);
    let job = prism_render::render::Job::share(&share);
    let sums = prism_render::render::render_share(&scene, &opts, &job, &|_| {});
    let (mut ours, mut theirs) = (Vec::new(), Vec::new());
    let mut mean_ours = [0f64; 3];
    let mut mean_theirs = [0f64; 3];
    let references = sums.pixels().iter().zip(reference.pixels());
    for ((p, r), v) in references.zip(variance.pixels()) {
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
    let z = prism_testkit::z_test(&ours, &theirs, 0.01, 1e-3);
    let width = reference.width() as usize;
    let (x, y) = (z.worst_pixel % width, z.worst_pixel / width);
    assert!(
        z.passed(),
        "{z:?}: pixel ({x}, {y}) prism {:?} vs Mitsuba {:?}",
        ours[z.worst_pixel],
        theirs[z.worst_pixel]
    );
    assert!(z.tested > 8_000, "{} pixels vary", z.tested);
}
