//! Building a [`Scene`] from a COLLADA document: instances placed in a Y-up world,
//! materials from bound effects, lights and the camera.
//!
//! Conventions (the CS184 reading of `FORMATS.md` section 2, made physical where the course
//! was not; `../shared/bench/pathtrace/dae_to_mitsuba.py` follows the same ones):
//! - A node's world matrix is the up-axis conversion times its node transforms.
//! - A CGL area light is a one-sided emitting rectangle, hittable by every ray.
//! - Point lights fall off with the inverse square of the distance.
//! - Shading normals are, by default, area-weighted vertex normals computed from the mesh
//!   (the course's halfedge normals), ignoring the file's normals.
//! - The camera is placed by the course's rule unless the file's own camera is asked for.

use prism_math::glam::{DMat4, DVec3, DVec4};
use prism_math::Loc;
use prism_math::{Rgb, Vec3, Warning};
use prism_mesh::vertex_normals_area_weighted;

use super::document::{Collada, Instance, MeshData, Shape};
use super::library::{CameraDef, EffectDef, LightKind};
use crate::error::SceneError;
use crate::scene::{
    Camera, CameraMode, Light, Material, NormalsMode, Scene, SceneOptions, SceneSphere, Shading,
    TriangleMesh,
};

fn v3(d: DVec3) -> Vec3 {
    d.as_vec3()
}

impl Scene {
    /// Builds a scene from a COLLADA document.
    ///
    /// # Errors
    /// [`SceneError::Element`] for a zero-area area light or a transform that makes a
    /// sphere's radius or a light's placement degenerate; `file` names the document.
    pub fn from_collada(
        doc: &Collada,
        opts: &SceneOptions,
        file: &str,
    ) -> Result<Scene, SceneError> {
        let up = doc.up_axis.to_y_up();
        let mut scene = Scene::new(Camera {
            eye: Vec3::ZERO,
            target: Vec3::NEG_Z,
            up: Vec3::Y,
            hfov: 50.0,
            vfov: 35.0,
            near: 0.001,
            far: 1000.0,
            lens: None,
            orthographic: None,
            crop: None,
        });
        scene.warnings.clone_from(&doc.warnings);
        let err = |line: u32, element: &str, message: String| SceneError::Element {
            at: Loc::line(file, line),
            element: element.to_string(),
            message,
        };
        // One scene material per effect used, plus the default diffuse.
        let mut effect_material: Vec<Option<usize>> = vec![None; doc.effects.len()];
        let mut default_material = None;
        let mut file_camera = None;
        // The first entry of each id, as a search in file order finds it.
        let mut material_by_id = std::collections::HashMap::new();
        for (id, effect) in &doc.materials {
            material_by_id.entry(id.as_str()).or_insert(effect);
        }
        let mut light_by_id = std::collections::HashMap::new();
        for l in &doc.lights {
            light_by_id.entry(l.id.as_str()).or_insert(l);
        }
        let mut warned_spot = false;
        for node in &doc.nodes {
            let world = up * node.world;
            for inst in &node.instances {
                match inst {
                    Instance::Geometry {
                        geometry,
                        materials,
                        defect,
                    } => {
                        let g = &doc.geometries[*geometry];
                        if let Some(e) = g.defect.as_ref().or(node.defect.as_ref()) {
                            return Err(e.clone());
                        }
                        // The node's first binding, as the course reads it.
                        let effect = match materials.first() {
                            None => None,
                            Some((_, target)) => {
                                match material_by_id.get(target.as_str()) {
                                    Some(Ok(e)) => Some(*e),
                                    Some(Err(e)) => return Err(e.clone()),
                                    // A missing first target is the binding's defect.
                                    None => match defect {
                                        Some(e) => return Err(e.clone()),
                                        None => None,
                                    },
                                }
                            }
                        };
                        if let Some(e) = effect.and_then(|e| doc.effects[e].defect.as_ref()) {
                            return Err(e.clone());
                        }
                        let material = match effect {
                            Some(e) => match effect_material[e] {
                                Some(m) => m,
                                None => {
                                    let m = effect_material_of(&doc.effects[e], file)?;
                                    scene.materials.push(m);
                                    effect_material[e] = Some(scene.materials.len() - 1);
                                    scene.materials.len() - 1
                                }
                            },
                            None => *default_material.get_or_insert_with(|| {
                                scene.materials.push(Material::Diffuse {
                                    reflectance: Rgb::splat(0.5),
                                    texture: None,
                                });
                                scene.materials.len() - 1
                            }),
                        };
                        match &g.shape {
                            Shape::Mesh(m) => {
                                let textured = matches!(
                                    scene.materials[material],
                                    Material::Diffuse {
                                        texture: Some(_),
                                        ..
                                    }
                                );
                                scene.meshes.push(mesh(
                                    m,
                                    world,
                                    material,
                                    &node.name,
                                    opts.normals,
                                    textured,
                                ));
                            }
                            Shape::Sphere { radius } => {
                                let center = world.transform_point3(DVec3::ZERO);
                                let scale = world.transform_vector3(DVec3::X).length();
                                let r = radius * scale;
                                if r.is_nan() || r <= 0.0 {
                                    return Err(err(
                                        node.line,
                                        "node",
                                        format!(
                                            "sphere {:?} has radius {r} after its transform",
                                            g.id
                                        ),
                                    ));
                                }
                                scene.spheres.push(SceneSphere {
                                    center: v3(center),
                                    radius: r as f32,
                                    material,
                                    inward: false,
                                    to_local: None,
                                });
                            }
                            Shape::Empty => {}
                        }
                    }
                    Instance::Light(id) => {
                        let Some(l) = light_by_id.get(id.as_str()) else {
                            continue;
                        };
                        if let Some(e) = l.defect.as_ref().or(node.defect.as_ref()) {
                            return Err(e.clone());
                        }
                        let at = |p: DVec3| world.transform_point3(p);
                        let center = at(DVec3::ZERO);
                        match l.kind {
                            LightKind::Point => scene.lights.push(Light::Point {
                                position: v3(center),
                                intensity: l.color,
                            }),
                            LightKind::Directional => {
                                // The course transforms the direction as a point.
                                let d = at(DVec3::NEG_Z);
                                let Some(direction) = d.try_normalize() else {
                                    return Err(err(
                                        node.line,
                                        "node",
                                        format!("directional light {id:?} has no direction"),
                                    ));
                                };
                                scene.lights.push(Light::Directional {
                                    direction: v3(direction),
                                    irradiance: l.color,
                                });
                            }
                            LightKind::Area => {
                                let dir = at(DVec3::NEG_Z) - center;
                                let dim_x = at(DVec3::NEG_X) - center;
                                let dim_y = at(DVec3::Y) - center;
                                let area = dim_x.cross(dim_y).length();
                                let normal = dir.try_normalize();
                                match normal {
                                    Some(n) if area > 0.0 && area.is_finite() => {
                                        let (c, dx, dy) = (v3(center), v3(dim_x), v3(dim_y));
                                        scene.lights.push(Light::Parallelogram {
                                            corner: c - 0.5 * dx - 0.5 * dy,
                                            edges: [dx, dy],
                                            colors: [l.color; 4],
                                            facing: Some(v3(n)),
                                        });
                                    }
                                    _ => {
                                        return Err(err(
                                            node.line,
                                            "node",
                                            format!("area light {id:?} has zero area (its node's matrix collapses the rectangle)"),
                                        ))
                                    }
                                }
                            }
                            LightKind::Ambient => {
                                scene.lights.push(Light::Hemisphere { radiance: l.color })
                            }
                            LightKind::Spot if !warned_spot => {
                                warned_spot = true;
                                scene.warnings.push(Warning::at(Loc::line(file, l.line), "spot lights are not rendered (the course's are black); skipped"));
                            }
                            LightKind::Spot => {}
                        }
                    }
                    Instance::Camera(id) => {
                        if file_camera.is_none() {
                            if let Some(c) = doc.cameras.iter().find(|c| &c.id == id) {
                                if let Some(e) = &c.defect {
                                    return Err(e.clone());
                                }
                                if let Some(e) = &node.defect {
                                    if opts.camera == CameraMode::File {
                                        return Err(e.clone());
                                    }
                                    scene.warnings.push(Warning::at(
                                        Loc::line(file, node.line),
                                        format!(
                                            "camera node {:?}: its transform is malformed; \
                                         the course's placement reads its direction from the \
                                         numbers given, in order",
                                            node.name
                                        ),
                                    ));
                                }
                                file_camera = Some((c.clone(), world));
                            }
                        }
                    }
                    // Every camera and light instance is read, to find the first camera.
                    Instance::Missing(e) => return Err(e.clone()),
                }
            }
        }
        scene.camera = place_camera(&scene, file_camera.as_ref(), opts.camera);
        Ok(scene)
    }
}

/// An effect's material, its diffuse texture read from the file it names (relative to the
/// document `file`) and its sRGB encoding undone.
fn effect_material_of(effect: &EffectDef, file: &str) -> Result<Material, SceneError> {
    let Some((name, line)) = &effect.diffuse_texture else {
        return Ok(effect.material.clone());
    };
    let located = |message: String| SceneError::Element {
        at: Loc::line(file, *line),
        element: "texture".to_string(),
        message,
    };
    let dir = std::path::Path::new(file)
        .parent()
        .unwrap_or(std::path::Path::new(""));
    // A regular file of bounded size (never a device that reads forever).
    let bytes = crate::obj::read_bytes(&dir.join(name))
        .map_err(|e| located(format!("{name}: cannot read the texture: {e}")))?;
    let image = crate::texture_file::decode_color_texture(&bytes, name)
        .map_err(|e| located(format!("{name}: {e}")))?;
    Ok(Material::Diffuse {
        reflectance: Rgb::WHITE,
        texture: Some(crate::MaterialTexture::new(
            name.clone(),
            std::sync::Arc::new(image),
        )),
    })
}

/// A mesh node's world-space triangles. With `uvs`, texture coordinates are kept: per
/// vertex when every corner of a vertex agrees, else every triangle corner becomes its own
/// vertex (shading normals computed first, then kept per corner).
fn mesh(
    m: &MeshData,
    world: DMat4,
    material: usize,
    name: &str,
    normals: NormalsMode,
    uvs: bool,
) -> TriangleMesh {
    let positions64: Vec<DVec3> = m
        .mesh
        .positions
        .iter()
        .map(|&p| {
            let q = world * DVec4::new(p.x, p.y, p.z, 1.0);
            q.truncate() / q.w
        })
        .collect();
    let mut triangles = Vec::new();
    let mut corners = Vec::new();
    let mut k = 0;
    for f in m.mesh.faces() {
        // Fan triangulation (the staged files hold triangles only).
        for i in 1..f.len() - 1 {
            triangles.push([f[0], f[i], f[i + 1]]);
            corners.push([k, k + i, k + i + 1]);
        }
        k += f.len();
    }
    let area = || {
        let mut p = prism_mesh::PolyMesh::new(positions64.clone(), &[]);
        for t in &triangles {
            p.push_face(t);
        }
        Shading::Smooth(
            vertex_normals_area_weighted(&p)
                .into_iter()
                .map(v3)
                .collect(),
        )
    };
    let shading = match (normals, &m.corner_normals) {
        (NormalsMode::Flat, _) => Shading::Flat,
        (NormalsMode::File, Some(cn)) => {
            let nm = prism_math::glam::DMat3::from_mat4(world)
                .inverse()
                .transpose();
            Shading::Corners(
                corners
                    .iter()
                    .map(|c| c.map(|i| v3((nm * cn[i]).normalize_or_zero())))
                    .collect(),
            )
        }
        _ => area(),
    };
    let positions: Vec<Vec3> = positions64.into_iter().map(v3).collect();
    let uv = |p: prism_math::glam::DVec2| prism_math::Vec2::new(p.x as f32, p.y as f32);
    match (&m.mesh.uvs, &m.corner_uvs) {
        (Some(per_vertex), _) if uvs => TriangleMesh {
            name: name.to_string(),
            positions,
            triangles,
            shading,
            material,
            uvs: Some(per_vertex.iter().map(|&p| uv(p)).collect()),
        },
        (None, Some(per_corner)) if uvs => {
            let shading = match shading {
                Shading::Smooth(n) => {
                    Shading::Corners(triangles.iter().map(|t| t.map(|i| n[i as usize])).collect())
                }
                other => other,
            };
            TriangleMesh {
                name: name.to_string(),
                positions: triangles
                    .iter()
                    .flat_map(|t| t.map(|i| positions[i as usize]))
                    .collect(),
                triangles: (0..triangles.len() as u32)
                    .map(|i| [3 * i, 3 * i + 1, 3 * i + 2])
                    .collect(),
                shading,
                material,
                uvs: Some(
                    corners
                        .iter()
                        .flat_map(|c| c.map(|k| uv(per_corner[k])))
                        .collect(),
                ),
            }
        }
        _ => TriangleMesh {
            name: name.to_string(),
            positions,
            triangles,
            shading,
            material,
            uvs: None,
        },
    }
}

fn place_camera(scene: &Scene, file: Option<&(CameraDef, DMat4)>, mode: CameraMode) -> Camera {
    let (mut hfov, mut vfov, mut near, mut far) = (50.0f64, 35.0f64, 0.001f64, 1000.0f64);
    if let Some((c, _)) = file {
        hfov = c.xfov.unwrap_or(50.0);
        vfov = match (c.yfov, c.aspect_ratio) {
            (Some(y), _) => y,
            (None, Some(a)) => 2.0 * ((hfov.to_radians() / 2.0).tan() / a).atan().to_degrees(),
            (None, None) => 35.0,
        };
        if c.xfov.is_none() {
            if let (Some(y), Some(a)) = (c.yfov, c.aspect_ratio) {
                hfov = 2.0 * ((y.to_radians() / 2.0).tan() * a).atan().to_degrees();
            }
        }
        near = c.znear;
        far = c.zfar;
    }
    let (eye, target, up) = match (mode, file) {
        (CameraMode::File, Some((_, w))) => {
            let eye = w.transform_point3(DVec3::ZERO);
            let fwd = w.transform_vector3(DVec3::NEG_Z);
            let up = w.transform_vector3(DVec3::Y);
            (v3(eye), v3(eye + fwd), v3(up))
        }
        _ => {
            // The point one unit in front of the camera, seen from the origin.
            let c_dir = file
                .map(|(_, w)| w.transform_point3(DVec3::NEG_Z))
                .and_then(DVec3::try_normalize)
                .unwrap_or(DVec3::Z);
            let (lo, hi) = scene.bounds().unwrap_or((Vec3::splat(-1.0), Vec3::ONE));
            let centre = ((lo + hi) * 0.5).as_dvec3();
            let r = 1.5 * f64::from((hi - lo).length());
            let mut phi = c_dir.y.clamp(-1.0, 1.0).acos();
            if phi.sin() == 0.0 {
                phi += 1e-5;
            }
            let theta = c_dir.x.atan2(c_dir.z);
            let dir = DVec3::new(phi.sin() * theta.sin(), phi.cos(), phi.sin() * theta.cos());
            (v3(centre + r * dir), v3(centre), Vec3::Y)
        }
    };
    Camera {
        eye,
        target,
        up,
        hfov: hfov as f32,
        vfov: vfov as f32,
        near: near as f32,
        far: far as f32,
        lens: None,
        orthographic: None,
        crop: None,
    }
}
