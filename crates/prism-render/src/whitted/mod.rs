//! The Whitted ray tracer of the Delft project, in one place: its scene (`scene`), orbit
//! camera (`camera`), Phong shading (`shading`), recursive tracer with its ray records
//! (`tracer`), the film that loops over pixels (`film`), a pixel's ray tree written out
//! (`debug`), and 3D segments drawn over a picture (`overlay`).

pub mod camera;
mod debug;
pub mod film;
pub mod overlay;
pub mod scene;
pub mod shading;
pub mod tracer;
