//! [`ObjDocument`]: what an OBJ file says (vertex data, faces as corners, and the material
//! and shape statements between them), read once by one set of rules and checked against
//! the memory budget; the mesh, the shading mesh and the Delft scene are built from it.

use prism_math::limits::{format_bytes, memory_budget};
use prism_math::Loc;

use super::lexer::{statements, ObjFloat, Statement};

/// Most corners one face may have.
pub const MAX_FACE_CORNERS: usize = 1 << 16;

/// What a reader keeps of a file beyond positions and faces. The grammar is the same
/// whatever is kept: every statement read is checked.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ObjOptions {
    /// Keep `vt` and `vn` data and the corners' `vt` and `vn` indices (a polygon mesh keeps
    /// positions only).
    pub attributes: bool,
    /// Keep `mtllib`, `usemtl`, `o` and `g` statements, in order among the faces (a scene
    /// groups its faces by them).
    pub markers: bool,
}

/// A face corner: 0-based indices into the positions, uvs and normals, in 12 bytes (a
/// document holds one per corner of the file).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Corner {
    /// The position.
    pub v: u32,
    /// The texture coordinate, or [`Corner::ABSENT`].
    vt: u32,
    /// The normal, or [`Corner::ABSENT`].
    vn: u32,
}

impl Corner {
    /// An index a corner does not name (no list holds 2^32 - 1 entries: the reader refuses
    /// files with as many).
    const ABSENT: u32 = u32::MAX;

    /// The corner of position `v`, texture coordinate `vt` and normal `vn`.
    ///
    /// # Panics
    /// If `vt` or `vn` is `u32::MAX`, which names no entry.
    #[must_use]
    pub fn new(v: u32, vt: Option<u32>, vn: Option<u32>) -> Corner {
        let index = |i: Option<u32>| {
            assert_ne!(i, Some(Corner::ABSENT), "an index below 2^32 - 1");
            i.unwrap_or(Corner::ABSENT)
        };
        Corner {
            v,
            vt: index(vt),
            vn: index(vn),
        }
    }

    /// The texture coordinate, if the corner names one (and the file has some).
    #[must_use]
    pub fn vt(&self) -> Option<u32> {
        (self.vt != Corner::ABSENT).then_some(self.vt)
    }

    /// The normal, if the corner names one (and the file has some).
    #[must_use]
    pub fn vn(&self) -> Option<u32> {
        (self.vn != Corner::ABSENT).then_some(self.vn)
    }
}

/// A face: its corners are `corners[first..first + count]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Face {
    /// Its first corner in [`ObjDocument::corners`].
    pub first: u32,
    /// How many corners (at least 3).
    pub count: u32,
    /// Its line.
    pub line: u32,
}

/// A statement that groups the faces after it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum MarkerKind {
    /// `mtllib NAME...`: material libraries.
    MaterialLibraries(Vec<String>),
    /// `usemtl NAME`: the material of the faces that follow.
    UseMaterial(String),
    /// `o` or `g`: a new shape or group.
    Shape,
}

/// A marker and where it stands: before face `before_face`, at line `line`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Marker {
    /// The number of faces before it.
    pub before_face: u32,
    /// Its line.
    pub line: u32,
    /// What it says.
    pub kind: MarkerKind,
}

/// A malformed or too large OBJ: where, and what was expected and found.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{at}: {message}")]
pub struct ObjError {
    /// The file and line.
    pub at: Loc,
    /// What was expected and what was found.
    pub message: String,
}

/// An OBJ file's content, in `F` precision.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ObjDocument<F> {
    /// `v` statements: x, y, z (a `w` is ignored).
    pub positions: Vec<[F; 3]>,
    /// `vt` statements: u, v (v is 0 if not given; a `w` is ignored).
    pub uvs: Vec<[F; 2]>,
    /// `vn` statements.
    pub normals: Vec<[F; 3]>,
    /// Every face's corners, face after face.
    pub corners: Vec<Corner>,
    /// The faces, in order.
    pub faces: Vec<Face>,
    /// The grouping statements, in order (with [`ObjOptions::markers`]).
    pub markers: Vec<Marker>,
}

impl<F: ObjFloat> ObjDocument<F> {
    /// The corners of face `f`.
    #[must_use]
    pub fn face_corners(&self, f: &Face) -> &[Corner] {
        &self.corners[f.first as usize..(f.first + f.count) as usize]
    }

    /// Reads OBJ text; `file` names it in errors. Statements: `v`, `vt`, `vn`, `f` (corners
    /// `v`, `v/vt`, `v//vn`, `v/vt/vn`, 1-based or negative from the end; in a file that has
    /// defined no `vt` (`vn`) so far, a corner's `vt` (`vn`) must still be a non-zero
    /// integer and reads as none), `mtllib`, `usemtl`, `o`, `g`; others (`s`, `l`, `p`, ...)
    /// are ignored. Everything kept is counted against the memory budget as it grows.
    ///
    /// # Errors
    /// An [`ObjError`] at the first malformed statement, or where the budget runs out.
    pub fn parse(text: &str, file: &str, options: ObjOptions) -> Result<Self, ObjError> {
        Self::parse_within(text, file, options, memory_budget())
    }

    /// [`ObjDocument::parse`] holding at most `budget` bytes.
    fn parse_within(
        text: &str,
        file: &str,
        options: ObjOptions,
        budget: u64,
    ) -> Result<Self, ObjError> {
        let mut doc = ObjDocument::<F>::default();
        let (mut uv_count, mut normal_count) = (0usize, 0usize);
        let mut held = 0u64;
        let mut corners = Vec::new();
        for st in statements(text) {
            let err = |message: String| ObjError {
                at: Loc::line(file, st.line),
                message,
            };
            let grew = match st.key {
                "v" => {
                    doc.positions.push(st.numbers::<F, 3>(3).map_err(err)?);
                    size_of::<[F; 3]>()
                }
                "vt" => {
                    let [u, v, _] = st.numbers::<F, 3>(1).map_err(err)?;
                    uv_count += 1;
                    if !options.attributes {
                        continue;
                    }
                    doc.uvs.push([u, v]);
                    size_of::<[F; 2]>()
                }
                "vn" => {
                    let n = st.numbers::<F, 3>(3).map_err(err)?;
                    normal_count += 1;
                    if !options.attributes {
                        continue;
                    }
                    doc.normals.push(n);
                    size_of::<[F; 3]>()
                }
                "f" => {
                    corners.clear();
                    for w in st.words() {
                        let counts = (doc.positions.len(), uv_count, normal_count);
                        let mut c = corner(w, counts).map_err(err)?;
                        if !options.attributes {
                            c = Corner::new(c.v, None, None);
                        }
                        corners.push(c);
                        if corners.len() > MAX_FACE_CORNERS {
                            return Err(err(format!(
                                "f: more than {MAX_FACE_CORNERS} corners in one face"
                            )));
                        }
                    }
                    if corners.len() < 3 {
                        return Err(err(format!(
                            "f: expected at least 3 corners, found {}",
                            corners.len()
                        )));
                    }
                    let first = u32::try_from(doc.corners.len())
                        .map_err(|_| err("f: more than 2^32 corners in one file".into()))?;
                    doc.corners.extend_from_slice(&corners);
                    doc.faces.push(Face {
                        first,
                        count: corners.len() as u32,
                        line: st.line,
                    });
                    corners.len() * size_of::<Corner>() + size_of::<Face>()
                }
                "mtllib" | "usemtl" | "o" | "g" if options.markers => {
                    doc.markers.push(marker(&st, doc.faces.len() as u32));
                    size_of::<Marker>()
                }
                _ => continue,
            };
            held += grew as u64;
            if held > budget {
                // The file's whole need is not known here, only that it passes the budget.
                return Err(err(format!(
                    "{}: the file's data passes the memory budget of {} here (--max-memory \
                     raises it)",
                    st.key,
                    format_bytes(budget)
                )));
            }
        }
        Ok(doc)
    }
}

/// The marker statement `st`, before face `before_face`.
fn marker(st: &Statement<'_>, before_face: u32) -> Marker {
    let kind = match st.key {
        "mtllib" => MarkerKind::MaterialLibraries(st.words().map(str::to_string).collect()),
        "usemtl" => MarkerKind::UseMaterial(st.rest().to_string()),
        _ => MarkerKind::Shape,
    };
    Marker {
        before_face,
        line: st.line,
        kind,
    }
}

/// Parses one face corner, given how many positions, uvs and normals are defined so far.
fn corner(w: &str, (positions, uvs, normals): (usize, usize, usize)) -> Result<Corner, String> {
    let mut parts = w.split('/');
    let index = |s: &str, n: usize, what: &str| -> Result<u32, String> {
        let i: i64 = s
            .parse()
            .map_err(|_| format!("f: expected a {what} index, found {w:?}"))?;
        let idx = if i > 0 { i - 1 } else { n as i64 + i };
        if i == 0 || idx < 0 || idx >= n as i64 {
            return Err(format!(
                "f: {what} index {i} is out of range ({n} defined so far)"
            ));
        }
        // Lists of 2^32 - 1 entries or more never fit the memory budget.
        u32::try_from(idx)
            .ok()
            .filter(|&i| i != Corner::ABSENT)
            .ok_or_else(|| format!("f: {what} index {i} is past 2^32 - 2"))
    };
    let v = index(parts.next().unwrap_or(""), positions, "vertex")?;
    // A file with no `vt` (`vn`) so far still names a number there, which reads as none (the
    // Delft template's rule: the uv is then (0, 0), the normal the geometric one).
    let absent = |s: &str, what: &str| match s.parse::<i64>() {
        Ok(i) if i != 0 => Ok(None),
        _ => Err(format!("f: expected a {what} index, found {w:?}")),
    };
    let vt = match parts.next() {
        None | Some("") => None,
        Some(s) if uvs == 0 => absent(s, "texture coordinate")?,
        Some(s) => Some(index(s, uvs, "texture coordinate")?),
    };
    let vn = match parts.next() {
        None | Some("") => None,
        Some(s) if normals == 0 => absent(s, "normal")?,
        Some(s) => Some(index(s, normals, "normal")?),
    };
    if parts.next().is_some() {
        return Err(format!(
            "f: expected v, v/vt, v//vn or v/vt/vn, found {w:?}"
        ));
    }
    Ok(Corner::new(v, vt, vn))
}

#[cfg(test)]
mod tests {
    use super::*;

    const ALL: ObjOptions = ObjOptions {
        attributes: true,
        markers: true,
    };

    fn parse(text: &str, options: ObjOptions) -> Result<ObjDocument<f64>, String> {
        ObjDocument::<f64>::parse(text, "t.obj", options).map_err(|e| e.to_string())
    }

    /// The four corner forms, negative indices from the end, and the Delft rule for a file
    /// without `vt` or `vn`: the index must be a number and reads as none.
    #[test]
    fn corners_in_every_form() {
        assert_eq!(size_of::<Corner>(), 12);
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\nf 1 2/1 3//1\nf -3/-1/-1 2 3\n";
        let doc = parse(text, ALL).unwrap();
        let c = Corner::new;
        assert_eq!(
            doc.corners,
            [
                c(0, None, None),
                c(1, Some(0), None),
                c(2, None, Some(0)),
                c(0, Some(0), Some(0)),
                c(1, None, None),
                c(2, None, None),
            ]
        );
        let bare = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/5/7 2/1 3//2\n", ALL).unwrap();
        assert!(bare
            .corners
            .iter()
            .all(|c| c.vt().is_none() && c.vn().is_none()));
        assert_eq!(
            parse("v 0 0 0\nf 1/x 1 1\n", ALL).unwrap_err(),
            "t.obj:2: f: expected a texture coordinate index, found \"1/x\""
        );
        assert_eq!(
            parse("v 0 0 0\nf 1/1/1/1 1 1\n", ALL).unwrap_err(),
            "t.obj:2: f: expected v, v/vt, v//vn or v/vt/vn, found \"1/1/1/1\""
        );
    }

    /// Without attributes, `vt` and `vn` are still checked (the grammar is one) but not kept.
    #[test]
    fn options_choose_what_is_kept_not_what_is_valid() {
        let text = "v 0 0 0\nvt 0.5\nvn 0 0 1\ng a\nusemtl m\nf 1/1/1 1 1\n";
        let kept = parse(text, ALL).unwrap();
        assert_eq!(kept.uvs, [[0.5, 0.0]]);
        assert_eq!(kept.corners[0].vt(), Some(0));
        assert_eq!(kept.markers.len(), 2);
        let plain = parse(text, ObjOptions::default()).unwrap();
        assert!(plain.uvs.is_empty() && plain.normals.is_empty() && plain.markers.is_empty());
        assert_eq!(plain.corners[0], Corner::new(0, None, None));
        let bad = "v 0 0 0\nvt 0 x\nf 1 1 1\n";
        for options in [ALL, ObjOptions::default()] {
            assert_eq!(
                parse(bad, options).unwrap_err(),
                "t.obj:2: vt: expected a finite number, found \"x\""
            );
        }
    }

    /// Markers keep their place among the faces.
    #[test]
    fn markers_stand_between_faces() {
        let text = "mtllib a.mtl b.mtl\nv 0 0 0\nf 1 1 1\no next\nusemtl red\nf 1 1 1\n";
        let doc = parse(text, ALL).unwrap();
        let kinds: Vec<(u32, u32, MarkerKind)> = doc
            .markers
            .into_iter()
            .map(|m| (m.before_face, m.line, m.kind))
            .collect();
        assert_eq!(
            kinds,
            [
                (
                    0,
                    1,
                    MarkerKind::MaterialLibraries(vec!["a.mtl".into(), "b.mtl".into()])
                ),
                (1, 4, MarkerKind::Shape),
                (1, 5, MarkerKind::UseMaterial("red".into())),
            ]
        );
    }

    /// A file that would hold more than the memory budget stops where the budget runs out:
    /// three positions (72 bytes in f64) fit in 80 bytes, the fourth does not.
    #[test]
    fn a_file_over_the_budget_is_refused_where_it_runs_out() {
        let text = "v 0 0 0\n".repeat(5);
        let read = |n: usize| {
            ObjDocument::<f64>::parse_within(&text[..8 * n], "t.obj", ALL, 80)
                .map_err(|e| e.to_string())
        };
        assert!(read(3).is_ok());
        let e = read(5).unwrap_err();
        assert_eq!(
            e,
            "t.obj:4: v: the file's data passes the memory budget of 80 B here (--max-memory \
             raises it)"
        );
    }
}
