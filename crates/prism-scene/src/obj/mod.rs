//! Wavefront OBJ scenes as the Delft ray tracer loads them: `v`, `vt`, `vn`, n-gon faces,
//! `mtllib`, `usemtl`, `o`/`g` shapes; one sub-mesh per run of faces with one material,
//! vertices de-duplicated on (position, normal, uv), and the optional normalisation to the
//! unit sphere around the vertices' mean.

mod mtl;

use std::collections::{HashMap, HashSet};
use std::path::Path;
use std::sync::Arc;

use prism_math::{Rgb, Vec2, Vec3};

use crate::error::SceneError;
use crate::scene::{Material, MaterialTexture, OrbitCamera, Scene, Shading, TriangleMesh};

pub(crate) use mtl::parse_mtl;

/// Largest OBJ or MTL file read (1 GiB).
pub const MAX_OBJ_BYTES: u64 = 1 << 30;
/// Most corners one face may have.
pub const MAX_FACE_CORNERS: usize = 1 << 16;

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
    prism_math::limits::read_input(path, MAX_OBJ_BYTES).map_err(|e| SceneError::Io {
        path: path.display().to_string(),
        source: Arc::new(e),
    })
}

/// Reads a text file of at most [`MAX_OBJ_BYTES`].
pub(crate) fn read_text(path: &Path) -> Result<String, SceneError> {
    let bytes = read_bytes(path)?;
    String::from_utf8(bytes).map_err(|e| SceneError::Line {
        file: path.display().to_string(),
        line: 1 + e.as_bytes()[..e.utf8_error().valid_up_to()]
            .iter()
            .filter(|&&b| b == b'\n')
            .count() as u32,
        message: "expected UTF-8 text".into(),
    })
}

/// One non-empty line of an OBJ or MTL file, comments removed.
pub(crate) struct Statement<'t> {
    /// 1-based line.
    pub line: u32,
    /// The first word.
    pub key: &'t str,
    /// The whole line, trimmed, the key included.
    pub content: &'t str,
}

impl Statement<'_> {
    /// An error at this line of `file`.
    pub fn error(&self, file: &str, message: String) -> SceneError {
        SceneError::Line {
            file: file.to_string(),
            line: self.line,
            message,
        }
    }
}

/// The statements of OBJ or MTL text, in order.
pub(crate) fn statements(text: &str) -> impl Iterator<Item = Statement<'_>> {
    text.lines().enumerate().filter_map(|(ln, raw)| {
        let content = raw.split('#').next().unwrap_or("").trim();
        let key = content.split_whitespace().next()?;
        Some(Statement {
            line: (ln + 1) as u32,
            key,
            content,
        })
    })
}

/// One corner of a face: indices into the position, uv and normal lists.
#[derive(Clone, Copy)]
struct Corner {
    v: usize,
    vt: Option<usize>,
    vn: Option<usize>,
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
    let mut positions: Vec<Vec3> = Vec::new();
    let mut uvs: Vec<Vec2> = Vec::new();
    let mut normals: Vec<Vec3> = Vec::new();
    let mut libs: Vec<mtl::MtlMaterial> = Vec::new();
    // Each material's index by name, the last definition winning (as a search from the end).
    let mut by_name: HashMap<String, usize> = HashMap::new();
    let mut lib_files: Vec<String> = Vec::new();
    let mut lib_names: HashSet<String> = HashSet::new();
    // Faces are stored as corners: their count is checked against the memory budget.
    let most_triangles = prism_math::limits::memory_budget() / size_of::<[Corner; 3]>() as u64;
    let mut triangle_count = 0u64;
    let mut runs: Vec<Run> = Vec::new();
    let mut current: Option<usize> = None;
    // A shape boundary (`o`, `g`) or a material change starts a new run.
    let mut new_run = true;
    let mut corners: Vec<Corner> = Vec::new();
    for st in statements(text) {
        let (key, content) = (st.key, st.content);
        let err = |message: String| st.error(file, message);
        let mut words = content.split_whitespace().skip(1);
        let mut numbers = |n: usize, what: &str| -> Result<[f32; 3], SceneError> {
            let mut out = [0.0; 3];
            for (k, slot) in out.iter_mut().take(n).enumerate() {
                let w = words
                    .next()
                    .ok_or_else(|| err(format!("{key}: expected {n} {what}, found {k}")))?;
                *slot = w
                    .parse::<f32>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| err(format!("{key}: expected a finite number, found {w:?}")))?;
            }
            Ok(out)
        };
        match key {
            "v" => positions.push(Vec3::from_array(numbers(3, "coordinates")?)),
            "vn" => normals.push(Vec3::from_array(numbers(3, "coordinates")?)),
            "vt" => {
                let [u, v, _] = numbers(2, "coordinates")?;
                uvs.push(Vec2::new(u, v));
            }
            "mtllib" => {
                for name in content[key.len()..].split_whitespace() {
                    // Each library is read once, however often or however it is named.
                    if !lib_names.insert(same_file_key(name)) {
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
                        by_name.insert(m.name.clone(), libs.len());
                        libs.push(m);
                    }
                    lib_files.push(name.to_string());
                }
            }
            "usemtl" => {
                let name = content[key.len()..].trim();
                let Some(&found) = by_name.get(name) else {
                    return Err(err(if lib_files.is_empty() {
                        format!("usemtl {name}: no material library was named before it")
                    } else {
                        format!(
                            "usemtl {name}: no such material in {}",
                            lib_files.join(", ")
                        )
                    }));
                };
                if current != Some(found) {
                    new_run = true;
                }
                current = Some(found);
            }
            "o" | "g" => new_run = true,
            "f" => {
                corners.clear();
                for w in words {
                    corners.push(corner(w, &positions, &uvs, &normals).map_err(&err)?);
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
                if new_run || runs.is_empty() {
                    runs.push(Run {
                        material: current,
                        triangles: Vec::new(),
                    });
                    new_run = false;
                }
                triangle_count += corners.len() as u64 - 2;
                if triangle_count > most_triangles {
                    let need = triangle_count * size_of::<[Corner; 3]>() as u64;
                    let over = prism_math::limits::check_memory(need).expect_err("over the budget");
                    return Err(err(format!("f: storing the faces {over}")));
                }
                let run = runs.last_mut().expect("a run was just ensured");
                // A fan from the first corner: a quad becomes (0 1 2) and (0 2 3).
                for i in 1..corners.len() - 1 {
                    run.triangles.push([corners[0], corners[i], corners[i + 1]]);
                }
            }
            _ => {}
        }
    }

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

/// Parses one face corner: `v`, `v/vt`, `v//vn` or `v/vt/vn`, 1-based or negative.
fn corner(w: &str, positions: &[Vec3], uvs: &[Vec2], normals: &[Vec3]) -> Result<Corner, String> {
    let mut parts = w.split('/');
    let index = |s: &str, n: usize, what: &str| -> Result<usize, String> {
        let i: i64 = s
            .parse()
            .map_err(|_| format!("f: expected a {what} index, found {w:?}"))?;
        let idx = if i > 0 { i - 1 } else { n as i64 + i };
        if i == 0 || idx < 0 || idx >= n as i64 {
            return Err(format!(
                "f: {what} index {i} is out of range ({n} defined so far)"
            ));
        }
        Ok(idx as usize)
    };
    let v = index(parts.next().unwrap_or(""), positions.len(), "vertex")?;
    // A file with no `vt` (no `vn`) at all gets (0, 0) (the geometric normal) wherever a
    // corner names one, as the template does.
    // A file with no `vt` (no `vn`) still names a number there.
    let number = |s: &str, what: &str| match s.parse::<i64>() {
        Ok(i) if i != 0 => Ok(None),
        _ => Err(format!("f: expected a {what} index, found {w:?}")),
    };
    let vt = match parts.next() {
        None | Some("") => None,
        Some(s) if uvs.is_empty() => number(s, "texture coordinate")?,
        Some(s) => Some(index(s, uvs.len(), "texture coordinate")?),
    };
    let vn = match parts.next() {
        None | Some("") => None,
        Some(s) if normals.is_empty() => number(s, "normal")?,
        Some(s) => Some(index(s, normals.len(), "normal")?),
    };
    if parts.next().is_some() {
        return Err(format!(
            "f: expected v, v/vt, v//vn or v/vt/vn, found {w:?}"
        ));
    }
    Ok(Corner { v, vt, vn })
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
                        file: m.file.clone(),
                        line: *line,
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
            Some(MaterialTexture {
                path: name.clone(),
                image,
            })
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
        let [p0, p1, p2] = tri.map(|c| positions[c.v]);
        let geometric = (p1 - p0).cross(p2 - p0).normalize_or_zero();
        let mut t = [0u32; 3];
        for (j, c) in tri.iter().enumerate() {
            let p = positions[c.v];
            let n = c.vn.map_or(geometric, |i| normals[i]);
            let uv = c.vt.map_or(Vec2::ZERO, |i| uvs[i]);
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
