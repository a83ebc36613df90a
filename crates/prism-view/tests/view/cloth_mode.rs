//! The cloth mode driven headlessly: its frames against the simulation stepped directly,
//! and what play, pause, step, reset, shaders and orbiting do.

use prism_cloth::{read_scene, Cloth};
use prism_view::{ClothMode, Input, Key, Mode, Viewer};

fn key(c: char) -> Input {
    Input::Key {
        key: Key::Char(c),
        ctrl: false,
    }
}

fn mode() -> ClothMode {
    let path = prism_testkit::shared_asset("clothsim/scene/pinned2.json");
    let scene = read_scene(&path, &[]).unwrap();
    ClothMode::new(scene, &path)
}

/// Oracle: the simulation stepped directly. Three drawn frames while playing are three
/// simulated frames, bit for bit; paused, drawing does not advance it; `N` advances one;
/// `R` goes back to the start.
#[test]
fn frames_are_the_simulation_stepped() {
    let mut m = mode();
    let path = prism_testkit::shared_asset("clothsim/scene/pinned2.json");
    let mut direct = Cloth::new(&read_scene(&path, &[]).unwrap());
    for _ in 0..3 {
        m.draw(64, 48);
        direct.frame();
    }
    assert_eq!(m.frames(), 3);
    assert_eq!(m.cloth().positions, direct.positions);
    assert!(m.busy());
    m.input(&key('p'), (64, 48));
    assert!(!m.busy());
    m.draw(64, 48);
    assert_eq!(m.frames(), 3);
    m.input(&key('n'), (64, 48));
    direct.frame();
    assert_eq!(m.frames(), 4);
    assert_eq!(m.cloth().positions, direct.positions);
    m.input(&key('r'), (64, 48));
    assert_eq!(m.frames(), 0);
    assert_eq!(
        m.cloth().positions,
        Cloth::new(&read_scene(&path, &[]).unwrap()).positions
    );
    assert!(m.status().starts_with("frame 0 | paused | phong"));
}

/// `C` moves to the next shader (the picture changes); dragging orbits the camera (the
/// picture changes); `P` plays again.
#[test]
fn shaders_orbit_and_play() {
    let mut v = Viewer::new(Box::new(mode()), 96, 72);
    v.input(key('p'));
    let phong = v.picture().clone();
    assert!(v.input(key('c')));
    assert!(v.mode().status().contains("diffuse"));
    let diffuse = v.picture().clone();
    assert_ne!(phong, diffuse);
    for _ in 0..3 {
        v.input(key('c'));
    }
    assert!(v.mode().status().contains("phong"));
    v.input(Input::Cursor { x: 10.0, y: 30.0 });
    v.input(Input::Button(true));
    assert!(v.input(Input::Cursor { x: 40.0, y: 30.0 }));
    v.input(Input::Button(false));
    assert_ne!(v.picture(), &phong);
    v.input(key('p'));
    assert!(v.busy());
}
