//! The limits the Mitsuba reader checks before it reads or builds: file size, includes,
//! objects, and the sizes a scene may ask for.

/// Largest scene file read, in bytes (each included file too).
pub const MAX_MITSUBA_BYTES: u64 = 256 << 20;

/// Deepest chain of `<include>`s followed.
pub const MAX_INCLUDE_DEPTH: usize = 16;

/// Most files one scene may read as XML (itself and its includes).
pub const MAX_SCENE_FILES: usize = 256;

/// Most plugin objects in one scene.
pub const MAX_OBJECTS: usize = 1_000_000;

/// Deepest nesting of objects followed through references (a `<ref>` to an object that
/// holds it is a cycle, and stops here).
pub const MAX_OBJECT_DEPTH: usize = 32;

/// Largest film side, in pixels.
pub const MAX_FILM_SIDE: u32 = 16384;

/// Most samples per pixel a scene may ask for.
pub const MAX_SAMPLE_COUNT: u32 = 1 << 20;

/// Most triangles and spheres in one scene, instances' copies included (about 3 GB to
/// render).
pub const MAX_SCENE_PRIMITIVES: usize = 20_000_000;

/// Most distinct rough plastic coats in one scene (each is tabulated by quadrature once, in
/// tens of milliseconds, and kept for the process).
pub const MAX_ROUGH_PLASTIC_COATS: usize = 256;

/// Segments around a `cylinder`: its silhouette is within 5e-6 of its radius.
pub const CYLINDER_SEGMENTS: u32 = 1024;

/// Segments of the triangle fan a `disk` becomes: its area is within 3e-5 of the disk's.
pub const DISK_SEGMENTS: u32 = 512;
