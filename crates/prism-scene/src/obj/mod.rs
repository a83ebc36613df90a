//! Wavefront OBJ scenes as the Delft ray tracer loads them: `v`, `vt`, `vn`, n-gon faces,
//! `mtllib`, `usemtl`, `o`/`g` shapes; one sub-mesh per run of faces with one material,
//! vertices de-duplicated on (position, normal, uv), and the optional normalisation to the
//! unit sphere around the vertices' mean.

mod mtl;

use std::collections::{HashMap, HashSet};
use std::path::Path;
use std::sync::Arc;

use prism_math::Loc;
use prism_math::{Rgb, Vec2, Vec3};
use prism_mesh::obj::{Corner, Marker, MarkerKind, ObjDocument};
pub use prism_mesh::obj::{ObjOptions, MAX_FACE_CORNERS};

use crate::error::SceneError;
use crate::scene::{Material, MaterialTexture, OrbitCamera, Scene, Shading, TriangleMesh};

pub(crate) use mtl::parse_mtl;

/// Largest OBJ or MTL file read (1 GiB).
pub const MAX_OBJ_BYTES: u64 = 1 << 30;

/// A source of an OBJ's companion files (MTL libraries, textures) by their name as
/// written in the file: the bytes, or a located error.
pub type Companions<'a> = dyn Fn(&str) -> Result<Vec<u8>, SceneError> + 'a;

/// Reads the OBJ scene in `path`, its MTL libraries and textures relative to its folder;
/// `normalize` moves the vertices' mean to the origin and scales the farthest vertex to
/// distance 1 (the Delft presets' `loadMesh(path, true)`).
///
/// # Errors
/// A [`SceneError`] naming the file and line of what is missing or malformed.
pub fn read_obj_scene(path: &Path, normalize: bool) -> Result<Scene, SceneError> {
    let text = read_text(path)?;
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let companions = |name: &str| read_bytes(&dir.join(name));
    parse_obj_scene(&text, &path.display().to_string(), &companions, normalize)
}

/// Reads a regular file of at most [`MAX_OBJ_BYTES`].
pub(crate) fn read_bytes(path: &Path) -> Result<Vec<u8>, SceneError> {
    read_bytes_within(path, MAX_OBJ_BYTES)
}

/// Reads a regular file of at most `limit` bytes.
fn read_bytes_within(path: &Path, limit: u64) -> Result<Vec<u8>, SceneError> {
    prism_math::limits::read_input(path, limit).map_err(|e| SceneError::Io {
        path: path.display().to_string(),
        source: Arc::new(e),
    })
}

/// Reads a text file of at most [`MAX_OBJ_BYTES`].
pub(crate) fn read_text(path: &Path) -> Result<String, SceneError> {
    read_text_within(path, MAX_OBJ_BYTES)
}

/// Reads a text file of at most `limit` bytes.
pub(crate) fn read_text_within(path: &Path, limit: u64) -> Result<String, SceneError> {
    let bytes = read_bytes_within(path, limit)?;
    String::from_utf8(bytes).map_err(|e| SceneError::Line {
        at: Loc::line(
            &path.display().to_string(),
            1 + e.as_bytes()[..e.utf8_error().valid_up_to()]
                .iter()
                .filter(|&&b| b == b'\n')
                .count() as u32,
        ),
        message: "expected UTF-8 text".into(),
    })
}

/// The materials an OBJ's libraries define, and the one its faces are using.
#[derive(Default)]
struct Materials {
    libs: Vec<mtl::MtlMaterial>,
    /// Each material's index by name, the last definition winning (as a search from the end).
    by_name: HashMap<String, usize>,
    /// The libraries read, as named.
    files: Vec<String>,
    /// The libraries read, as [`same_file_key`]s.
    keys: HashSet<String>,
    current: Option<usize>,
}

impl Materials {
    /// Applies marker `m` of `file`: reads the libraries it names (each once, however often
    /// or however it is named), or takes the material it names. True if it starts a new run
    /// of faces (a shape, or another material).
    fn apply(
        &mut self,
        m: &Marker,
        file: &str,
        companions: &Companions<'_>,
    ) -> Result<bool, SceneError> {
        let err = |message: String| SceneError::Line {
            at: Loc::line(file, m.line),
            message,
        };
        match &m.kind {
            MarkerKind::MaterialLibraries(names) => {
                for name in names {
                    if !self.keys.insert(same_file_key(name)) {
                        continue;
                    }
                    let bytes = companions(name).map_err(|e| {
                        err(format!("mtllib: cannot read the material library: {e}"))
                    })?;
                    let what = Path::new(file)
                        .parent()
                        .unwrap_or(Path::new(""))
                        .join(name)
                        .display()
                        .to_string();
                    let text = String::from_utf8(bytes)
                        .map_err(|_| err(format!("mtllib {name}: expected UTF-8 text")))?;
                    for m in parse_mtl(&text, &what)? {
                        self.by_name.insert(m.name.clone(), self.libs.len());
                        self.libs.push(m);
                    }
                    self.files.push(name.to_string());
                }
                Ok(false)
            }
            MarkerKind::UseMaterial(name) => {
                let Some(&found) = self.by_name.get(name) else {
                    return Err(err(if self.files.is_empty() {
                        format!("usemtl {name}: no material library was named before it")
                    } else {
                        format!(
                            "usemtl {name}: no such material in {}",
                            self.files.join(", ")
                        )
                    }));
                };
                let changed = self.current != Some(found);
                self.current = Some(found);
                Ok(changed)
            }
            MarkerKind::Shape => Ok(true),
        }
    }
}

/// A run of triangles with one material, as corners.
struct Run {
    material: Option<usize>,
    triangles: Vec<[Corner; 3]>,
}

/// Parses OBJ text; `file` names it in errors, `companions` gives the MTL libraries and
/// textures it names; `normalize` as in [`read_obj_scene`]. The scene's camera is the
/// Delft default ([`OrbitCamera::default`]); it has no lights.
///
/// # Errors
/// A [`SceneError`] naming the file and line of what is missing or malformed.
pub fn parse_obj_scene(
    text: &str,
    file: &str,
    companions: &Companions<'_>,
    normalize: bool,
) -> Result<Scene, SceneError> {
    let options = ObjOptions {
        attributes: true,
        markers: true,
    };
    let doc = ObjDocument::<f32>::parse(text, file, options).map_err(SceneError::from)?;
    let positions: Vec<Vec3> = doc.positions.iter().map(|&p| Vec3::from_array(p)).collect();
    let uvs: Vec<Vec2> = doc.uvs.iter().map(|&t| Vec2::from_array(t)).collect();
    let normals: Vec<Vec3> = doc.normals.iter().map(|&n| Vec3::from_array(n)).collect();
    let mut materials = Materials::default();
    // Faces become fans of triangles: their count is checked against the memory budget.
    let most_triangles = prism_math::limits::memory_budget() / size_of::<[Corner; 3]>() as u64;
    let mut triangle_count = 0u64;
    let mut runs: Vec<Run> = Vec::new();
    // A shape boundary (`o`, `g`) or a material change starts a new run.
    let mut new_run = true;
    let mut markers = doc.markers.iter().peekable();
    for (index, face) in doc.faces.iter().enumerate() {
        while let Some(m) = markers.next_if(|m| m.before_face as usize <= index) {
            new_run |= materials.apply(m, file, companions)?;
        }
        let corners = doc.face_corners(face);
        if new_run || runs.is_empty() {
            runs.push(Run {
                material: materials.current,
                triangles: Vec::new(),
            });
            new_run = false;
        }
        triangle_count += corners.len() as u64 - 2;
        if triangle_count > most_triangles {
            let need = triangle_count * size_of::<[Corner; 3]>() as u64;
            let over = prism_math::limits::check_memory(need).expect_err("over the budget");
            return Err(SceneError::Line {
                at: Loc::line(file, face.line),
                message: format!("f: storing the faces {over}"),
            });
        }
        let run = runs.last_mut().expect("a run was just ensured");
        // A fan from the first corner: a quad becomes (0 1 2) and (0 2 3).
        for i in 1..corners.len() - 1 {
            run.triangles.push([corners[0], corners[i], corners[i + 1]]);
        }
    }
    // Libraries and materials named after the last face are still read and checked.
    for m in markers {
        materials.apply(m, file, companions)?;
    }
    let libs = materials.libs;

    let mut scene = Scene::new(OrbitCamera::default().to_camera(1.0));
    // Materials in the order they are first used; faces without one share the default.
    let mut material_slot: HashMap<Option<usize>, usize> = HashMap::new();
    let mut textures = TextureCache::new();
    for run in &runs {
        if run.triangles.is_empty() {
            continue;
        }
        let slot = match material_slot.get(&run.material) {
            Some(&s) => s,
            None => {
                let (m, name) = match run.material {
                    None => (
                        Material::Phong {
                            kd: Rgb::WHITE,
                            ks: Rgb::BLACK,
                            shininess: 1.0,
                            kd_texture: None,
                            transparency: 1.0,
                        },
                        "(none)".to_string(),
                    ),
                    Some(i) => (
                        to_material(&libs[i], companions, &mut textures)?,
                        libs[i].name.clone(),
                    ),
                };
                scene.materials.push(m);
                scene.material_names.push(name);
                material_slot.insert(run.material, scene.materials.len() - 1);
                scene.materials.len() - 1
            }
        };
        scene
            .meshes
            .push(build_mesh(run, slot, &positions, &uvs, &normals, &scene));
    }
    if normalize {
        normalize_meshes(&mut scene.meshes);
    }
    Ok(scene)
}

/// A companion file's name with the spellings of one path made one (`./a//b.mtl`, `a/b.mtl`
/// and `a/c/../b.mtl` alike), so that a file named many ways is read once.
fn same_file_key(name: &str) -> String {
    use std::path::Component;
    let mut parts: Vec<String> = Vec::new();
    for c in Path::new(name).components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir if parts.last().is_some_and(|p| p != "..") => {
                parts.pop();
            }
            c => parts.push(c.as_os_str().to_string_lossy().into_owned()),
        }
    }
    parts.join("/")
}

/// Textures decoded so far, by their name in the MTL file: each is read and decoded once.
type TextureCache = HashMap<String, Arc<prism_image::RgbImage>>;

/// A Phong material from an MTL entry, its texture loaded (once, through `textures`).
fn to_material(
    m: &mtl::MtlMaterial,
    companions: &Companions<'_>,
    textures: &mut TextureCache,
) -> Result<Material, SceneError> {
    let kd_texture = match &m.kd_map {
        None => None,
        Some((name, line)) => {
            let image = match textures.entry(same_file_key(name)) {
                std::collections::hash_map::Entry::Occupied(e) => Arc::clone(e.get()),
                std::collections::hash_map::Entry::Vacant(slot) => {
                    let located = |message: String| SceneError::Line {
                        at: Loc::line(&m.file.clone(), *line),
                        message,
                    };
                    let bytes = companions(name).map_err(|e| {
                        located(format!(
                            "material {}: map_Kd {name}: cannot read the texture: {e}",
                            m.name
                        ))
                    })?;
                    let image = crate::texture_file::decode_texture(&bytes, name)
                        .map_err(|e| located(format!("material {}: map_Kd {name}: {e}", m.name)))?;
                    Arc::clone(slot.insert(Arc::new(image)))
                }
            };
            Some(MaterialTexture::new(name.clone(), image))
        }
    };
    Ok(Material::Phong {
        kd: m.kd,
        ks: m.ks,
        shininess: m.shininess,
        kd_texture,
        transparency: m.dissolve,
    })
}

/// Key of a vertex for de-duplication: the bits of its values, with -0 read as 0.
fn vertex_key(p: Vec3, n: Vec3, uv: Vec2) -> [u32; 8] {
    let b = |x: f32| if x == 0.0 { 0 } else { x.to_bits() };
    [
        b(p.x),
        b(p.y),
        b(p.z),
        b(n.x),
        b(n.y),
        b(n.z),
        b(uv.x),
        b(uv.y),
    ]
}

/// One sub-mesh: vertices de-duplicated on (position, normal, uv); a corner without `vn`
/// takes its triangle's geometric normal, one without `vt` (0, 0).
fn build_mesh(
    run: &Run,
    material: usize,
    positions: &[Vec3],
    uvs: &[Vec2],
    normals: &[Vec3],
    scene: &Scene,
) -> TriangleMesh {
    let mut cache: HashMap<[u32; 8], u32> = HashMap::new();
    let mut mesh_positions = Vec::new();
    let mut mesh_normals = Vec::new();
    let mut mesh_uvs = Vec::new();
    let mut triangles = Vec::with_capacity(run.triangles.len());
    for tri in &run.triangles {
        let [p0, p1, p2] = tri.map(|c| positions[c.v as usize]);
        let geometric = (p1 - p0).cross(p2 - p0).normalize_or_zero();
        let mut t = [0u32; 3];
        for (j, c) in tri.iter().enumerate() {
            let p = positions[c.v as usize];
            let n = c.vn().map_or(geometric, |i| normals[i as usize]);
            let uv = c.vt().map_or(Vec2::ZERO, |i| uvs[i as usize]);
            t[j] = *cache.entry(vertex_key(p, n, uv)).or_insert_with(|| {
                mesh_positions.push(p);
                mesh_normals.push(n);
                mesh_uvs.push(uv);
                (mesh_positions.len() - 1) as u32
            });
        }
        triangles.push(t);
    }
    TriangleMesh {
        name: scene.material_name(material),
        positions: mesh_positions,
        triangles,
        shading: Shading::Smooth(mesh_normals),
        material,
        uvs: Some(mesh_uvs),
    }
}

/// Moves the mean of every mesh vertex to the origin and scales the farthest to distance
/// 1 (a scene whose vertices all coincide is only moved).
fn normalize_meshes(meshes: &mut [TriangleMesh]) {
    let count: usize = meshes.iter().map(|m| m.positions.len()).sum();
    if count == 0 {
        return;
    }
    let sum = meshes
        .iter()
        .flat_map(|m| m.positions.iter())
        .fold(Vec3::ZERO, |a, &p| a + p);
    let center = sum / count as f32;
    let max_d = meshes
        .iter()
        .flat_map(|m| m.positions.iter())
        .fold(0.0f32, |a, &p| a.max((p - center).length()));
    let scale = if max_d > 0.0 { max_d } else { 1.0 };
    for m in meshes {
        for p in &mut m.positions {
            *p = (*p - center) / scale;
        }
    }
}

#[cfg(test)]
mod tests;
