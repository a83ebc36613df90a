//! [`MeshMode`]: MeshEdit's controls on a halfedge mesh: orbit (drag), zoom (wheel) and pan
//! (arrows); the vertex, edge or face under the cursor highlighted; `F` flip, `S` split,
//! `C` collapse the highlighted edge, `U` one level of Loop subdivision, `N` smooth or flat
//! normals, `W` wireframe, `Ctrl+Z` undo, `Ctrl+S` save as `NAME-edited.obj` (or `-2`, `-3`, ... if taken). An operation
//! the mesh cannot take says why on the status line and changes nothing.

use std::cell::OnceCell;
use std::path::{Path, PathBuf};

use prism_accel::{BuildOptions, Bvh};
use prism_image::Rgb8Image;
use prism_math::glam::DVec3;
use prism_math::{Ray, Rgb, Vec3};
use prism_mesh::{loop_subdivide, EdgeId, FaceId, HalfedgeMesh, LoopWeights, VertexId};
use prism_shade::{shade_rgb8, ShadeMesh, ShadeOptions, Shader, Uniforms, View};

use crate::input::{Input, Key};
use crate::orbit::Orbit;
use crate::viewer::{Mode, Response};

/// What is under the cursor.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Hover {
    /// A vertex.
    Vertex(VertexId),
    /// An edge.
    Edge(EdgeId),
    /// A face.
    Face(FaceId),
}

/// Undo keeps this many meshes.
const UNDO: usize = 32;

/// A mesh in the viewer.
pub struct MeshMode {
    path: PathBuf,
    mesh: HalfedgeMesh,
    undo: Vec<HalfedgeMesh>,
    shade: ShadeMesh,
    flat: bool,
    wireframe: bool,
    orbit: Orbit,
    pan: Vec3,
    home: (Vec3, f32),
    hover: Option<Hover>,
    cursor: (f64, f64),
    /// The faces' BVH for picking, built at the first hover after a change.
    picker: OnceCell<Picker>,
}

/// The mesh's faces as triangles (fans from their first corner) in prism's one BVH, and
/// the face each triangle belongs to.
struct Picker {
    bvh: Bvh,
    face_of: Vec<FaceId>,
}

impl Picker {
    fn new(m: &HalfedgeMesh) -> Picker {
        let mut triangles = Vec::new();
        let mut face_of = Vec::new();
        for fi in 0..m.face_count() as u32 {
            let f = FaceId(fi);
            let corners: Vec<Vec3> = (m.face_halfedges(f))
                .map(|h| m.position(m.origin(h)).as_vec3())
                .collect();
            for i in 1..corners.len().saturating_sub(1) {
                triangles.push([corners[0], corners[i], corners[i + 1]]);
                face_of.push(f);
            }
        }
        Picker {
            bvh: Bvh::build(&triangles, &[], &BuildOptions::default()),
            face_of,
        }
    }
}

/// The mesh drawn: fans of its faces, one vertex per corner for flat normals.
fn shade_mesh(mesh: &HalfedgeMesh, flat: bool) -> ShadeMesh {
    let poly = mesh.to_polymesh();
    let mut s = ShadeMesh::from_polymesh(&poly);
    if flat {
        let mut f = ShadeMesh::default();
        for t in &s.triangles {
            let p = t.map(|i| s.positions[i as usize]);
            let n = (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero();
            let base = f.positions.len() as u32;
            f.positions.extend(p);
            f.normals.extend([n; 3]);
            f.uvs.extend([prism_math::Vec2::ZERO; 3]);
            f.triangles.push([base, base + 1, base + 2]);
        }
        f.compute_tangents();
        s = f;
    }
    s
}

impl MeshMode {
    /// A viewer of `mesh`, read from `path`.
    #[must_use]
    pub fn new(mesh: HalfedgeMesh, path: &Path) -> MeshMode {
        let shade = shade_mesh(&mesh, false);
        let (lo, hi) = shade.bounds().unwrap_or((Vec3::ZERO, Vec3::ONE));
        let centre = (lo + hi) * 0.5;
        let radius = ((hi - lo).length() * 0.5).max(1e-6);
        MeshMode {
            path: path.to_path_buf(),
            mesh,
            undo: Vec::new(),
            shade,
            flat: false,
            wireframe: true,
            orbit: Orbit::default(),
            pan: Vec3::ZERO,
            home: (centre, radius),
            hover: None,
            cursor: (0.0, 0.0),
            picker: OnceCell::new(),
        }
    }

    /// The mesh.
    #[must_use]
    pub fn mesh(&self) -> &HalfedgeMesh {
        &self.mesh
    }

    /// What the cursor is over.
    #[must_use]
    pub fn hover(&self) -> Option<Hover> {
        self.hover
    }

    /// The camera at `w x h`.
    fn view(&self, w: u32, h: u32) -> View {
        let (centre, radius) = self.home;
        let target = centre + self.pan;
        let eye = target + Vec3::new(0.0, 0.0, 2.8 * radius);
        View {
            eye: self.orbit.eye(eye, target),
            target,
            up: Vec3::Y,
            fov_y: 45.0,
            width: w.max(1),
            height: h.max(1),
        }
    }

    /// The vertex, edge or face under pixel `(x, y)` of a `size` window.
    fn pick(&self, x: f64, y: f64, size: (u32, u32)) -> Option<Hover> {
        let view = self.view(size.0, size.1);
        let inverse = view.clip_from_world().ok()?.inverse();
        let ndc_x = (2.0 * x / f64::from(size.0) - 1.0) as f32;
        let ndc_y = (1.0 - 2.0 * y / f64::from(size.1)) as f32;
        let o = inverse.point(Vec3::new(ndc_x, ndc_y, -1.0));
        let far = inverse.point(Vec3::new(ndc_x, ndc_y, 1.0));
        let d = (far - o).normalize_or_zero();
        let m = &self.mesh;
        let picker = self.picker.get_or_init(|| Picker::new(m));
        let found = picker.bvh.intersect(&Ray::new(o, d), 0.0, f32::INFINITY)?;
        let f = picker.face_of[found.prim as usize];
        let p = o.as_dvec3() + d.as_dvec3() * f64::from(found.t);
        // The nearest corner or side of the face, if near enough; else the face.
        let hs: Vec<_> = m.face_halfedges(f).collect();
        let size_of = hs
            .iter()
            .map(|&h| (m.position(m.dest(h)) - m.position(m.origin(h))).length())
            .fold(0.0, f64::max);
        let (v, dv) = hs
            .iter()
            .map(|&h| (m.origin(h), (m.position(m.origin(h)) - p).length()))
            .min_by(|a, b| a.1.total_cmp(&b.1))?;
        if dv < 0.12 * size_of {
            return Some(Hover::Vertex(v));
        }
        let (e, de) = hs
            .iter()
            .map(|&h| {
                let (a, b) = (m.position(m.origin(h)), m.position(m.dest(h)));
                (m.edge(h), segment_distance(p, a, b))
            })
            .min_by(|a, b| a.1.total_cmp(&b.1))?;
        if de < 0.2 * size_of {
            Some(Hover::Edge(e))
        } else {
            Some(Hover::Face(f))
        }
    }

    /// Runs an edit on a copy; on success it becomes the mesh (the old one goes on the undo
    /// stack), on failure the message says why.
    fn edit(
        &mut self,
        what: &str,
        f: impl FnOnce(&mut HalfedgeMesh, EdgeId) -> Result<(), String>,
    ) -> Response {
        let Some(Hover::Edge(e)) = self.hover else {
            return Response::Message(format!("{what}: point at an edge first"));
        };
        let mut copy = self.mesh.clone();
        match f(&mut copy, e) {
            Ok(()) => {
                self.commit(copy);
                // A flipped or split edge keeps its number: it stays highlighted, so that
                // S right after F splits it. A collapse renumbers, so nothing stays.
                if what != "collapse" && (e.0 as usize) < self.mesh.edge_count() {
                    self.hover = Some(Hover::Edge(e));
                }
                Response::Message(format!("{what} edge {}", e.0))
            }
            Err(why) => Response::Message(format!("cannot {what} edge {}: {why}", e.0)),
        }
    }

    fn commit(&mut self, mesh: HalfedgeMesh) {
        self.undo.push(std::mem::replace(&mut self.mesh, mesh));
        if self.undo.len() > UNDO {
            self.undo.remove(0);
        }
        self.shade = shade_mesh(&self.mesh, self.flat);
        self.hover = None;
        self.picker = OnceCell::new();
    }

    fn save(&self) -> Response {
        let stem = self
            .path
            .file_stem()
            .map_or("mesh".into(), |s| s.to_string_lossy().into_owned());
        // A new file each time, never over an earlier one: NAME-edited.obj, then
        // NAME-edited-2.obj, ...
        let out = (1..)
            .map(|n| match n {
                1 => self.path.with_file_name(format!("{stem}-edited.obj")),
                n => self.path.with_file_name(format!("{stem}-edited-{n}.obj")),
            })
            .find(|p| std::fs::symlink_metadata(p).is_err())
            .expect("a free name");
        let poly = self.mesh.to_polymesh();
        let written = prism_image::write_atomic(&out, |w| {
            prism_mesh::write_obj(&poly, w).map_err(|source| prism_image::ImageError::Io {
                path: out.clone(),
                source,
            })
        });
        match written {
            Ok(()) => Response::Message(format!("saved {}", out.display())),
            Err(e) => Response::Message(format!("not saved: {e}")),
        }
    }
}

/// Distance from `p` to the segment `ab`.
fn segment_distance(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    let ab = b - a;
    let t = ((p - a).dot(ab) / ab.length_squared().max(1e-300)).clamp(0.0, 1.0);
    (a + ab * t - p).length()
}

impl Mode for MeshMode {
    fn name(&self) -> &'static str {
        "mesh"
    }

    fn title(&self) -> String {
        format!("prism view: {} (mesh)", self.path.display())
    }

    fn help(&self) -> Vec<(&'static str, &'static str)> {
        vec![
            (
                "hover",
                "highlight the vertex, edge or face under the cursor",
            ),
            ("F S C", "flip, split, collapse the highlighted edge"),
            ("U", "one level of Loop subdivision"),
            ("N", "smooth / flat normals"),
            ("W", "wireframe on / off"),
            ("Ctrl+Z", "undo"),
            ("Ctrl+S", "save as NAME-edited.obj (-2, -3, ... if taken)"),
            ("drag", "orbit"),
            ("wheel", "zoom"),
            ("arrows", "pan"),
            ("R", "reset the view"),
        ]
    }

    fn input(&mut self, input: &Input, size: (u32, u32)) -> Response {
        match *input {
            Input::Key { key, ctrl: true } => match key {
                Key::Char('z') => match self.undo.pop() {
                    Some(m) => {
                        self.mesh = m;
                        self.shade = shade_mesh(&self.mesh, self.flat);
                        self.hover = None;
                        self.picker = OnceCell::new();
                        Response::Message("undone".into())
                    }
                    None => Response::Message("nothing to undo".into()),
                },
                Key::Char('s') => self.save(),
                _ => Response::Ignored,
            },
            Input::Key { key, ctrl: false } => match key {
                Key::Char('f') => self.edit("flip", |m, e| m.flip(e).map_err(|x| x.to_string())),
                Key::Char('s') => self.edit("split", |m, e| {
                    m.split(e).map(|_| ()).map_err(|x| x.to_string())
                }),
                Key::Char('c') => self.edit("collapse", |m, e| {
                    m.collapse(e).map(|_| ()).map_err(|x| x.to_string())
                }),
                Key::Char('u') => {
                    let next = loop_subdivide(&self.mesh, LoopWeights::Warren)
                        .and_then(|p| HalfedgeMesh::from_polymesh(&p));
                    match next {
                        Ok(m) => {
                            let faces = m.face_count();
                            self.commit(m);
                            Response::Message(format!("subdivided: {faces} faces"))
                        }
                        Err(e) => Response::Message(format!("cannot subdivide: {e}")),
                    }
                }
                Key::Char('n') => {
                    self.flat = !self.flat;
                    self.shade = shade_mesh(&self.mesh, self.flat);
                    Response::Redraw
                }
                Key::Char('w') => {
                    self.wireframe = !self.wireframe;
                    Response::Redraw
                }
                Key::Char('r') => {
                    self.orbit.reset();
                    self.pan = Vec3::ZERO;
                    Response::Redraw
                }
                Key::Left | Key::Right | Key::Up | Key::Down => {
                    let step = 0.1 * self.home.1;
                    self.pan += match key {
                        Key::Left => Vec3::new(-step, 0.0, 0.0),
                        Key::Right => Vec3::new(step, 0.0, 0.0),
                        Key::Up => Vec3::new(0.0, step, 0.0),
                        _ => Vec3::new(0.0, -step, 0.0),
                    };
                    Response::Redraw
                }
                _ => Response::Ignored,
            },
            Input::Cursor { x, y } => {
                self.cursor = (x, y);
                if self.orbit.input(input, size.0) == Some(true) {
                    return Response::Redraw;
                }
                let hover = self.pick(x, y, size);
                if hover == self.hover {
                    Response::Ignored
                } else {
                    self.hover = hover;
                    Response::Redraw
                }
            }
            Input::Button(_) | Input::Wheel(_) => {
                if self.orbit.input(input, size.0) == Some(true) {
                    Response::Redraw
                } else {
                    Response::Ignored
                }
            }
            Input::Resize { .. } => Response::Redraw,
        }
    }

    fn draw(&mut self, width: u32, height: u32) -> Rgb8Image {
        let view = self.view(width, height);
        let opts = ShadeOptions {
            background: Rgb::new(0.15, 0.15, 0.18),
            wireframe: self.wireframe.then_some(Rgb::new(0.0, 0.0, 0.0)),
            ..ShadeOptions::default()
        };
        let mut image = shade_rgb8(
            &self.shade,
            &view,
            &Shader::Phong,
            &Uniforms::default(),
            &opts,
        )
        .unwrap_or_else(|_| Rgb8Image::new(width, height, [128, 128, 128]));
        let Ok(clip) = view.clip_from_world() else {
            return image;
        };
        let screen = |p: DVec3| -> Option<(f32, f32)> {
            let c = clip.point_homogeneous(p.as_vec3());
            (c.w > 1e-6).then(|| {
                (
                    (c.x / c.w + 1.0) * 0.5 * width as f32,
                    (1.0 - c.y / c.w) * 0.5 * height as f32,
                )
            })
        };
        let m = &self.mesh;
        let gold = [255, 200, 0];
        match self.hover {
            Some(Hover::Vertex(v)) => {
                if let Some((x, y)) = screen(m.position(v)) {
                    for dy in -3i64..=3 {
                        for dx in -3i64..=3 {
                            put(&mut image, x as i64 + dx, y as i64 + dy, gold);
                        }
                    }
                }
            }
            Some(Hover::Edge(e)) => {
                let h = m.edge_halfedge(e);
                if let (Some(a), Some(b)) = (
                    screen(m.position(m.origin(h))),
                    screen(m.position(m.dest(h))),
                ) {
                    line(&mut image, a, b, gold);
                }
            }
            Some(Hover::Face(f)) => {
                for h in m.face_halfedges(f) {
                    if let (Some(a), Some(b)) = (
                        screen(m.position(m.origin(h))),
                        screen(m.position(m.dest(h))),
                    ) {
                        line(&mut image, a, b, [0, 200, 255]);
                    }
                }
            }
            None => {}
        }
        image
    }

    fn status(&self) -> String {
        let m = &self.mesh;
        let hover = match self.hover {
            Some(Hover::Vertex(v)) => format!("vertex {}", v.0),
            Some(Hover::Edge(e)) => format!("edge {}", e.0),
            Some(Hover::Face(f)) => format!("face {}", f.0),
            None => "-".into(),
        };
        format!(
            "{} vertices, {} edges, {} faces | {} | {} normals | under the cursor: {hover}",
            m.vertex_count(),
            m.edge_count(),
            m.face_count(),
            if self.wireframe {
                "wireframe"
            } else {
                "no wireframe"
            },
            if self.flat { "flat" } else { "smooth" }
        )
    }
}

fn put(image: &mut Rgb8Image, x: i64, y: i64, c: [u8; 3]) {
    if x >= 0 && y >= 0 && (x as u32) < image.width() && (y as u32) < image.height() {
        image.set(x as u32, y as u32, c);
    }
}

/// A line three pixels wide from `a` to `b`.
fn line(image: &mut Rgb8Image, a: (f32, f32), b: (f32, f32), c: [u8; 3]) {
    let len = ((b.0 - a.0).hypot(b.1 - a.1)).min(1e5);
    let steps = (len.ceil() as i64).max(1);
    for i in 0..=steps {
        let t = i as f32 / steps as f32;
        let (x, y) = (a.0 + (b.0 - a.0) * t, a.1 + (b.1 - a.1) * t);
        for d in -1..=1 {
            put(image, x as i64 + d, y as i64, c);
            put(image, x as i64, y as i64 + d, c);
        }
    }
}
