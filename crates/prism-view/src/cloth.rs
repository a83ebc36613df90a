//! [`ClothMode`]: the course's ClothSim scene played in the window as its app plays it: one
//! simulated frame (30 steps) a drawn frame, `P` play or pause, `N` one frame, `R` back to
//! the start, `C` the next shader (Phong, diffuse, normal, wireframe), drag to orbit and the
//! wheel to move closer.

use std::path::{Path, PathBuf};
use std::time::Instant;

use prism_cloth::{cloth_mesh, course_view, obstacles, Cloth, ClothScene};
use prism_image::Rgb8Image;
use prism_shade::{shade_rgb8, ShadeOptions, Shader, Uniforms, View};

use crate::input::{Input, Key};
use crate::orbit::Orbit;
use crate::viewer::{Mode, Response};

/// The shaders `C` cycles through, by name.
const SHADERS: [&str; 4] = ["phong", "diffuse", "normal", "wireframe"];

fn shader(i: usize) -> Shader {
    match i % SHADERS.len() {
        0 => Shader::Phong,
        1 => Shader::Diffuse,
        2 => Shader::Normal,
        _ => Shader::Wireframe,
    }
}

/// A cloth simulation in the viewer.
pub struct ClothMode {
    path: PathBuf,
    scene: ClothScene,
    cloth: Cloth,
    /// The course app's camera, from the starting masses.
    view: View,
    playing: bool,
    frames: u32,
    shader: usize,
    orbit: Orbit,
    step_ms: f64,
    diverged: Option<u32>,
}

impl ClothMode {
    /// A viewer of `scene`, read from `path`, playing from its start.
    #[must_use]
    pub fn new(scene: ClothScene, path: &Path) -> ClothMode {
        let cloth = Cloth::new(&scene);
        let view = course_view(&cloth, 1, 1);
        ClothMode {
            path: path.to_path_buf(),
            scene,
            cloth,
            view,
            playing: true,
            frames: 0,
            shader: 0,
            orbit: Orbit::default(),
            step_ms: 0.0,
            diverged: None,
        }
    }

    /// Frames simulated since the start.
    #[must_use]
    pub fn frames(&self) -> u32 {
        self.frames
    }

    /// The simulation.
    #[must_use]
    pub fn cloth(&self) -> &Cloth {
        &self.cloth
    }

    /// Simulates one frame; a diverged simulation stops and says so.
    fn step(&mut self) {
        if self.diverged.is_some() {
            return;
        }
        let t = Instant::now();
        self.cloth.frame();
        self.step_ms = t.elapsed().as_secs_f64() * 1e3;
        self.frames += 1;
        if !self.cloth.is_finite() {
            self.diverged = Some(self.frames);
            self.playing = false;
        }
    }
}

impl Mode for ClothMode {
    fn name(&self) -> &'static str {
        "cloth"
    }

    fn title(&self) -> String {
        format!("prism view: {} (cloth)", self.path.display())
    }

    fn help(&self) -> Vec<(&'static str, &'static str)> {
        vec![
            ("P", "play / pause"),
            ("N", "one frame (30 steps), paused"),
            ("R", "back to the start"),
            ("C", "next shader: phong, diffuse, normal, wireframe"),
            ("drag", "orbit the camera"),
            ("wheel", "move the camera closer or farther"),
        ]
    }

    fn input(&mut self, input: &Input, size: (u32, u32)) -> Response {
        match *input {
            Input::Key { key, ctrl: false } => match key {
                Key::Char('p') => {
                    if self.diverged.is_some() {
                        return Response::Message(
                            "the simulation diverged: R starts it again".into(),
                        );
                    }
                    self.playing = !self.playing;
                    Response::Redraw
                }
                Key::Char('n') => {
                    self.playing = false;
                    self.step();
                    Response::Redraw
                }
                Key::Char('r') => {
                    self.cloth = Cloth::new(&self.scene);
                    self.frames = 0;
                    self.diverged = None;
                    Response::Redraw
                }
                Key::Char('c') => {
                    self.shader = (self.shader + 1) % SHADERS.len();
                    Response::Redraw
                }
                _ => Response::Ignored,
            },
            Input::Cursor { .. } | Input::Button(_) | Input::Wheel(_) => {
                if self.orbit.input(input, size.0) == Some(true) {
                    Response::Redraw
                } else {
                    Response::Ignored
                }
            }
            Input::Resize { .. } => Response::Redraw,
            Input::Key { .. } => Response::Ignored,
        }
    }

    fn draw(&mut self, width: u32, height: u32) -> Rgb8Image {
        if self.playing {
            self.step();
        }
        let mut mesh = cloth_mesh(&self.cloth);
        mesh.append(&obstacles(&self.scene));
        let view = View {
            eye: self.orbit.eye(self.view.eye, self.view.target),
            width,
            height,
            ..self.view
        };
        shade_rgb8(
            &mesh,
            &view,
            &shader(self.shader),
            &Uniforms::default(),
            &ShadeOptions::default(),
        )
        // A window's size is within the pipeline's limits; anything else shows grey.
        .unwrap_or_else(|_| Rgb8Image::new(width, height, [128, 128, 128]))
    }

    fn status(&self) -> String {
        let state = match (self.diverged, self.playing) {
            (Some(f), _) => format!("diverged in frame {f} (ks too stiff; R restarts)"),
            (None, true) => "playing".into(),
            (None, false) => "paused".into(),
        };
        format!(
            "frame {} | {state} | {} | step {:.1} ms",
            self.frames, SHADERS[self.shader], self.step_ms
        )
    }

    fn busy(&self) -> bool {
        self.playing
    }
}
