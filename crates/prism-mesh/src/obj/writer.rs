//! [`ObjWriter`], the one OBJ writer: vectors (`v`, `vt`, `vn`) and faces, each number in a
//! chosen [`NumberStyle`], and [`write_obj`], a polygon mesh through it.

use std::io::{self, Write};

use super::document::Corner;
use crate::PolyMesh;

/// How numbers are written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NumberStyle {
    /// The shortest decimal that reads back as the value, integers as `1.0`, tiny and huge
    /// values in exponent form (`1e-7`).
    Shortest,
    /// The shortest decimal that reads back as the value, without an exponent and integers
    /// without a point (`1`, `0.0000001`): Rust's `Display`.
    Plain,
}

/// A float an [`ObjWriter`] writes (`f32` or `f64`), at its own precision.
pub trait ObjNumber: Copy + std::fmt::Display {
    /// Appends the shortest round-trip decimal with an exponent where short.
    fn shortest(self, buffer: &mut ryu::Buffer, out: &mut Vec<u8>);
}

impl ObjNumber for f32 {
    fn shortest(self, buffer: &mut ryu::Buffer, out: &mut Vec<u8>) {
        out.extend_from_slice(buffer.format(self).as_bytes());
    }
}

impl ObjNumber for f64 {
    fn shortest(self, buffer: &mut ryu::Buffer, out: &mut Vec<u8>) {
        out.extend_from_slice(buffer.format(self).as_bytes());
    }
}

/// Writes OBJ statements to `out`, a line at a time.
pub struct ObjWriter<W: Write> {
    out: W,
    style: NumberStyle,
    line: Vec<u8>,
    float: ryu::Buffer,
    int: itoa::Buffer,
}

impl<W: Write> ObjWriter<W> {
    /// A writer to `out` with numbers in `style`.
    pub fn new(out: W, style: NumberStyle) -> ObjWriter<W> {
        ObjWriter {
            out,
            style,
            line: Vec::with_capacity(96),
            float: ryu::Buffer::new(),
            int: itoa::Buffer::new(),
        }
    }

    /// Writes `tag` (`v`, `vt`, `vn`) and `values`.
    ///
    /// # Errors
    /// Whatever the output returns.
    pub fn vector<F: ObjNumber>(&mut self, tag: &str, values: &[F]) -> io::Result<()> {
        self.line.clear();
        self.line.extend_from_slice(tag.as_bytes());
        for &v in values {
            self.line.push(b' ');
            match self.style {
                NumberStyle::Shortest => v.shortest(&mut self.float, &mut self.line),
                NumberStyle::Plain => {
                    write!(self.line, "{v}").expect("writing to memory");
                }
            }
        }
        self.line.push(b'\n');
        self.out.write_all(&self.line)
    }

    /// Writes a face of `corners` (0-based; written 1-based as `v`, `v/vt`, `v//vn` or
    /// `v/vt/vn`).
    ///
    /// # Errors
    /// Whatever the output returns.
    pub fn face(&mut self, corners: impl IntoIterator<Item = Corner>) -> io::Result<()> {
        self.line.clear();
        self.line.push(b'f');
        for c in corners {
            self.line.push(b' ');
            let index = |int: &mut itoa::Buffer, line: &mut Vec<u8>, i: u32| {
                line.extend_from_slice(int.format(u64::from(i) + 1).as_bytes());
            };
            index(&mut self.int, &mut self.line, c.v);
            match (c.vt(), c.vn()) {
                (None, None) => {}
                (Some(t), None) => {
                    self.line.push(b'/');
                    index(&mut self.int, &mut self.line, t);
                }
                (t, Some(n)) => {
                    self.line.push(b'/');
                    if let Some(t) = t {
                        index(&mut self.int, &mut self.line, t);
                    }
                    self.line.push(b'/');
                    index(&mut self.int, &mut self.line, n);
                }
            }
        }
        self.line.push(b'\n');
        self.out.write_all(&self.line)
    }
}

/// Writes positions, per-vertex normals (when present for every vertex, as `vn` lines with
/// `v//vn` corners) and faces as OBJ, with the shortest round-trip decimal for every number.
///
/// # Errors
/// Whatever the writer returns.
pub fn write_obj(mesh: &PolyMesh, out: &mut impl Write) -> io::Result<()> {
    let mut w = ObjWriter::new(out, NumberStyle::Shortest);
    let normals = mesh
        .normals
        .as_ref()
        .filter(|n| n.len() == mesh.vertex_count());
    for p in &mesh.positions {
        w.vector("v", &p.to_array())?;
    }
    for n in normals.into_iter().flatten() {
        w.vector("vn", &n.to_array())?;
    }
    for f in mesh.faces() {
        w.face(
            f.iter()
                .map(|&v| Corner::new(v, None, normals.is_some().then_some(v))),
        )?;
    }
    Ok(())
}
