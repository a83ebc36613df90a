//! prism-shade's integration tests: the pipeline's properties and closed forms (`pipeline`)
//! and the course's shaders against OpenGL's pictures (`opengl`).

mod opengl;
mod pipeline;
