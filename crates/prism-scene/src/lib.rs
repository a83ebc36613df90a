//! Floor-2 scene descriptions for prism: plain data read from files, from which runtime
//! structures (halfedge meshes, BVHs) are built.
//!
//! The reader here is COLLADA 1.4.1 ([`read_collada`], [`parse_collada`]): geometry
//! (`<polylist>`, `<triangles>`, `<polygons>`, the course's CGL spheres), the node hierarchy
//! with its transforms (`matrix`, `translate`, `rotate`, `scale`, `lookat`) and the up axis.
//! [`write_collada`] writes a polygon mesh back as a one-node COLLADA document.
//! [`read_mesh`] and [`write_mesh`] read and write mesh files of every format by extension
//! ([`MeshFormat`]: OBJ, PLY, COLLADA).
//!
//! The Delft ray tracer's inputs: OBJ scenes with MTL materials and textures
//! ([`read_obj_scene`]), its built-in scenes ([`Preset`]) and its TOML render
//! configuration ([`read_render_config`]); [`load_delft`] finds a scene named on the command
//! line among the three and lights a lone OBJ.
//! [`Scene::light_by_environment_map`] lights a scene by an environment map.
//!
//! [`Scene`] is what renderers consume: world-space meshes and spheres with materials,
//! lights and a camera, built from a document by [`Scene::from_collada`]; the module that
//! defines it reads no file. [`load`] reads a scene file by its extension.
#![warn(missing_docs)]

mod assets;
mod builtin;
mod collada;
mod delft;
mod environment;
mod error;
mod load;
mod mesh_io;
pub mod mitsuba;
mod obj;
mod presets;
mod render_config;
mod scene;
mod texture_file;

pub use assets::{course_assets, AssetsError, DATA_ENV};
pub use builtin::cornell_box;
pub use collada::{
    parse_collada, read_collada, write_collada, CameraDef, Collada, EffectDef, Geometry, Instance,
    LightDef, LightKind, MeshData, Node, Part, Shape, UpAxis, MAX_COLLADA_BYTES, MAX_NODES,
    MAX_NODE_DEPTH, MAX_PLACED_FACES,
};
pub use delft::{
    default_obj_lights, load_delft, mesh_names, read_environment_map, staged_data, DelftError,
    DelftScene, DelftWarning,
};
pub use environment::EnvironmentMapError;
pub use error::SceneError;
pub use load::load;
pub use mesh_io::{read_mesh, read_mesh_repaired, write_mesh, MeshFormat, MeshIoError};
pub use mitsuba::{
    read_document, read_mitsuba, read_mitsuba_with, to_scene as mitsuba_to_scene, Filter,
    MitsubaOptions, MitsubaScene, MitsubaSettings,
};
pub use obj::{parse_obj_scene, read_obj_scene, Companions, MAX_FACE_CORNERS, MAX_OBJ_BYTES};
pub use presets::Preset;
pub use render_config::{
    parse_render_config, read_render_config, EnvironmentMapFile, Extras, ExtrasTable, Features,
    MeshRef, Motion, RenderConfig, SceneSource, MAX_CONFIG_BYTES, MAX_EXTENT, MAX_EXTRA_SAMPLES,
    MAX_WINDOW_PIXELS, MAX_WINDOW_SIDE,
};
pub use scene::{
    Camera, CameraMode, Crop, EnvMapping, Light, Material, MaterialTexture, MicrofacetKind,
    NormalsMode, OrbitCamera, PrincipledWeight, Roughness, ScalarTexture, Scene, SceneOptions,
    SceneSphere, Shading, TexturedParameter, ThinLens, TiltOptions, TriangleMesh,
};
