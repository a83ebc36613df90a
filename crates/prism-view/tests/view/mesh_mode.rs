//! The mesh mode driven headlessly: hovering finds elements, and each edit equals the
//! halfedge mesh's own operation (the oracle), refused edits change nothing, undo restores.

use std::path::Path;

use prism_mesh::{parse_obj, HalfedgeMesh};
use prism_view::{Hover, Input, Key, MeshMode, Mode, Viewer};

const OCTAHEDRON: &str = "v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\n\
f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n";
const SQUARE: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n";

const SIZE: (u32, u32) = (120, 90);

fn scratch(name: &str) -> prism_testkit::Scratch {
    prism_testkit::scratch("prism-view-mesh", name)
}

fn mesh(obj: &str) -> HalfedgeMesh {
    HalfedgeMesh::from_polymesh(&parse_obj(obj, "m.obj").unwrap()).unwrap()
}

/// Moves the cursor over the window until it is over an element of the kind `want` picks.
fn find(mode: &mut MeshMode, want: fn(&Hover) -> bool) -> (f64, f64) {
    for y in (0..SIZE.1).step_by(2) {
        for x in (0..SIZE.0).step_by(2) {
            let (x, y) = (f64::from(x) + 0.5, f64::from(y) + 0.5);
            mode.input(&Input::Cursor { x, y }, SIZE);
            if mode.hover().is_some_and(|h| want(&h)) {
                return (x, y);
            }
        }
    }
    panic!("no such element under any pixel");
}

fn key(c: char, ctrl: bool) -> Input {
    Input::Key {
        key: Key::Char(c),
        ctrl,
    }
}

/// Oracle: the halfedge mesh's own flip and collapse. `F` on the hovered edge flips exactly
/// that edge, `C` collapses it; `Ctrl+Z` undoes each, back to the same faces.
#[test]
fn edits_are_the_halfedge_operations_and_undo() {
    let original = mesh(OCTAHEDRON);
    let mut m = MeshMode::new(original.clone(), Path::new("oct.obj"));
    m.draw(SIZE.0, SIZE.1);
    find(&mut m, |h| matches!(h, Hover::Edge(_)));
    let Some(Hover::Edge(e)) = m.hover() else {
        unreachable!()
    };
    let mut direct = original.clone();
    direct.flip(e).unwrap();
    assert_eq!(
        m.input(&key('f', false), SIZE),
        prism_view::Response::Message(format!("flip edge {}", e.0))
    );
    assert_eq!(m.mesh().to_polymesh(), direct.to_polymesh());
    // The flipped edge stays highlighted: S right after F splits that same edge.
    assert_eq!(m.hover(), Some(Hover::Edge(e)));
    direct.split(e).unwrap();
    m.input(&key('s', false), SIZE);
    assert_eq!(m.mesh().to_polymesh(), direct.to_polymesh());
    m.input(&key('z', true), SIZE);
    m.input(&key('z', true), SIZE);
    assert_eq!(m.mesh().to_polymesh(), original.to_polymesh());

    find(&mut m, |h| matches!(h, Hover::Edge(_)));
    let Some(Hover::Edge(e)) = m.hover() else {
        unreachable!()
    };
    let mut direct = original.clone();
    direct.collapse(e).unwrap();
    m.input(&key('c', false), SIZE);
    assert_eq!(m.mesh().to_polymesh(), direct.to_polymesh());
    assert_eq!(m.mesh().euler_characteristic(), 2);
    m.input(&key('z', true), SIZE);
    assert_eq!(m.mesh().to_polymesh(), original.to_polymesh());
    assert!(matches!(
        m.input(&key('z', true), SIZE),
        prism_view::Response::Message(ref s) if s == "nothing to undo"
    ));
    m.input(&key('u', false), SIZE);
    assert_eq!(
        m.mesh().face_count(),
        32,
        "Loop subdivision: four faces for each"
    );
}

/// Flipping a boundary edge is refused with the mesh's reason and changes nothing; an edit
/// with no edge under the cursor says to point at one; the background picks nothing.
#[test]
fn refused_edits_say_why() {
    let square = mesh(SQUARE);
    let mut m = MeshMode::new(square.clone(), Path::new("sq.obj"));
    m.input(&Input::Cursor { x: 0.5, y: 0.5 }, SIZE);
    assert_eq!(m.hover(), None);
    assert!(matches!(
        m.input(&key('f', false), SIZE),
        prism_view::Response::Message(ref s) if s == "flip: point at an edge first"
    ));
    find(&mut m, |h| match h {
        Hover::Edge(e) => square_boundary(*e),
        _ => false,
    });
    let reply = m.input(&key('f', false), SIZE);
    let prism_view::Response::Message(text) = reply else {
        panic!("no message")
    };
    assert!(text.starts_with("cannot flip edge"), "{text}");
    assert_eq!(m.mesh().to_polymesh(), square.to_polymesh());
}

fn square_boundary(e: prism_mesh::EdgeId) -> bool {
    mesh(SQUARE).is_boundary_edge(e)
}

/// `W` and `N` change the picture; `Ctrl+S` writes NAME-edited.obj next to the file, which
/// reads back as the mesh.
#[test]
fn wireframe_normals_and_save() {
    let dir = scratch("save");
    let path = dir.join("oct.obj");
    std::fs::write(&path, OCTAHEDRON).unwrap();
    let mut v = Viewer::new(
        Box::new(MeshMode::new(mesh(OCTAHEDRON), &path)),
        SIZE.0,
        SIZE.1,
    );
    let wired = v.picture().clone();
    v.input(key('w', false));
    assert_ne!(v.picture(), &wired);
    let smooth = v.picture().clone();
    v.input(key('n', false));
    assert_ne!(v.picture(), &smooth);
    assert!(v.mode().status().contains("flat normals"));
    v.input(key('s', true));
    let saved = dir.join("oct-edited.obj");
    assert_eq!(
        v.message(),
        Some(format!("saved {}", saved.display()).as_str())
    );
    let back = prism_mesh::read_obj(&saved).unwrap();
    assert_eq!(back, mesh(OCTAHEDRON).to_polymesh());
    // Saving again never writes over the earlier file.
    std::fs::write(&saved, "kept").unwrap();
    v.input(key('s', true));
    let second = dir.join("oct-edited-2.obj");
    assert_eq!(
        v.message(),
        Some(format!("saved {}", second.display()).as_str())
    );
    assert_eq!(std::fs::read_to_string(&saved).unwrap(), "kept");
    assert!(prism_mesh::read_obj(&second).is_ok());
}
