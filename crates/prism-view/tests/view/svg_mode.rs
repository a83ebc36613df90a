//! The SVG mode driven headlessly, event by event, each control checked against what it must
//! do to the state and to the picture.

use std::path::Path;

use prism_raster::{read_svg, Dialect};
use prism_view::{Input, Key, SvgMode, Viewer};

const TRIANGLE: &str = r#"<svg xmlns="http://www.w3.org/2000/svg" width="100" height="100">
  <polygon points="10,10 90,30 30,90" fill="black"/>
</svg>"#;

fn scratch(name: &str) -> prism_testkit::Scratch {
    prism_testkit::scratch("prism-view", name)
}

fn mode(dir: &Path) -> SvgMode {
    let path = dir.join("t.svg");
    std::fs::write(&path, TRIANGLE).unwrap();
    let doc = read_svg(&path, Dialect::Svg).unwrap();
    SvgMode::new(doc, &path, Dialect::Svg, dir)
}

fn viewer(dir: &Path) -> Viewer {
    Viewer::new(Box::new(mode(dir)), 200, 160)
}

fn key(c: char) -> Input {
    Input::Key {
        key: Key::Char(c),
        ctrl: false,
    }
}

/// Pixels neither black nor white: anti-aliased edges.
fn greys(v: &mut Viewer) -> usize {
    v.picture()
        .pixels()
        .iter()
        .filter(|p| p[0] != 0 && p[0] != 255)
        .count()
}

/// `=` and `-` step through 1, 4, 9 and 16 samples (stopping at the ends); at 1 sample the
/// triangle's edges are hard (every pixel black or white), at 16 they are smooth.
#[test]
fn sample_rate_keys_smooth_the_edges() {
    let dir = scratch("rate");
    let mut v = viewer(&dir);
    assert_eq!(greys(&mut v), 0, "one sample: no grey pixels");
    for expected in [4, 9, 16, 16] {
        assert!(v.input(key('=')));
        assert!(v.mode().status().starts_with(&format!("{expected} spp")));
    }
    assert!(greys(&mut v) > 50, "sixteen samples: grey edge pixels");
    for expected in [9, 4, 1, 1] {
        v.input(key('-'));
        assert!(v.mode().status().starts_with(&format!("{expected} spp")));
    }
    v.input(key('p'));
    assert!(v.mode().status().contains("pixel bilinear"));
    v.input(key('l'));
    v.input(key('l'));
    assert!(v.mode().status().contains("trilinear"));
}

/// Dragging by 40 pixels moves the picture by 40 pixels; `R` brings the first view back.
#[test]
fn drag_pans_and_r_resets() {
    let dir = scratch("pan");
    let mut v = viewer(&dir);
    let before = v.picture().clone();
    v.input(Input::Cursor { x: 100.0, y: 80.0 });
    v.input(Input::Button(true));
    assert!(v.input(Input::Cursor { x: 140.0, y: 80.0 }));
    v.input(Input::Button(false));
    // Moving without the button held does not pan.
    assert!(!v.input(Input::Cursor { x: 10.0, y: 10.0 }));
    let after = v.picture().clone();
    let (mut same, mut total) = (0, 0);
    for y in 0..160 {
        for x in 0..160 {
            total += 1;
            same += usize::from(after.get(x + 40, y) == before.get(x, y));
        }
    }
    assert!(
        same * 100 >= total * 99,
        "{same} of {total} pixels moved by 40"
    );
    v.input(key('r'));
    assert_eq!(v.picture(), &before);
}

/// The wheel zooms about the cursor: the drawing's point under the cursor stays there, and
/// the span shrinks by 1.25 a line.
#[test]
fn wheel_zooms_about_the_cursor() {
    let dir = scratch("zoom");
    use prism_view::Mode;
    let mut mode = mode(&dir);
    mode.draw(200, 160);
    let (cx, cy, span) = mode.region().unwrap();
    let under = |(cx, cy, span): (f64, f64, f64), x: f64, y: f64| {
        let s = 160.0 / (2.0 * span);
        (cx + (x - 100.0) / s, cy + (y - 80.0) / s)
    };
    let p0 = under((cx, cy, span), 150.0, 40.0);
    mode.input(&Input::Cursor { x: 150.0, y: 40.0 }, (200, 160));
    mode.input(&Input::Wheel(2.0), (200, 160));
    let r = mode.region().unwrap();
    assert!((r.2 - span / 1.5625).abs() < 1e-9 * span);
    let p1 = under(r, 150.0, 40.0);
    assert!((p0.0 - p1.0).abs() < 1e-9 && (p0.1 - p1.1).abs() < 1e-9);
}

/// `S` writes the picture as a PNG (a second one gets the next number) and says where; `H`
/// shows the help overlay over the picture; Esc asks to quit; a resize redraws at the new
/// size.
#[test]
fn screenshot_help_quit_and_resize() {
    let dir = scratch("shot");
    let mut v = viewer(&dir);
    let picture = v.picture().clone();
    assert!(v.input(key('s')));
    let first = dir.join("t-screenshot-1.png");
    assert_eq!(
        v.message(),
        Some(format!("saved {}", first.display()).as_str())
    );
    let saved = prism_image::read_png(&first).unwrap();
    assert_eq!(saved.to_rgb8(), picture);
    v.input(key('s'));
    assert!(dir.join("t-screenshot-2.png").exists());
    v.input(Input::Resize {
        width: 800,
        height: 600,
    });
    let plain = v.frame().image;
    assert!(v.input(key('h')));
    assert!(v.help_shown());
    let help = v.frame().image;
    assert_ne!(
        help.get(20, 20),
        plain.get(20, 20),
        "the overlay covers the corner"
    );
    assert_eq!(
        help.get(790, 300),
        plain.get(790, 300),
        "and not the whole picture"
    );
    assert!(!v.quit());
    v.input(Input::Key {
        key: Key::Escape,
        ctrl: false,
    });
    assert!(v.quit());
    v.input(Input::Resize {
        width: 64,
        height: 48,
    });
    let p = v.picture();
    assert_eq!((p.width(), p.height()), (64, 48));
}
