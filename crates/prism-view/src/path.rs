//! [`PathMode`]: a COLLADA scene path-traced progressively, one sample per pixel a frame, the
//! passes added with the film's exact pixel sums (so the picture after n passes is the
//! `prism render -s n` image); dragging orbits the camera and the wheel moves it closer, each
//! restarting the passes; `1`-`9` keep only the m-th bounce, `0` all of them; `A` shows the
//! noise heat map (where adaptive sampling would keep sampling).

use std::path::{Path, PathBuf};
use std::time::Instant;

use prism_image::{heat_colour, Image, Rgb8Image};
use prism_render::{render_share, PixelSum, RenderOptions, RenderScene, Share};

use crate::input::{Input, Key};
use crate::orbit::Orbit;
use crate::viewer::{Mode, Response};

/// Passes after which the picture is left as it is.
pub const MAX_PASSES: u32 = 4096;

/// A path-traced scene in the viewer.
pub struct PathMode {
    path: PathBuf,
    scene: RenderScene,
    base: prism_scene::Camera,
    orbit: Orbit,
    only_bounce: Option<u32>,
    heatmap: bool,
    seed: u64,
    sums: Option<Image<PixelSum>>,
    passes: u32,
    rate: f64,
}

impl PathMode {
    /// A viewer of `scene`, read from `path`, path-traced with `seed`.
    #[must_use]
    pub fn new(scene: &prism_scene::Scene, path: &Path, seed: u64) -> PathMode {
        PathMode {
            path: path.to_path_buf(),
            scene: RenderScene::new(scene),
            base: scene.camera,
            orbit: Orbit::default(),
            only_bounce: None,
            heatmap: false,
            seed,
            sums: None,
            passes: 0,
            rate: 0.0,
        }
    }

    /// Passes (samples per pixel) added so far.
    #[must_use]
    pub fn passes(&self) -> u32 {
        self.passes
    }

    /// The camera after the orbit: the base camera's eye turned about its target.
    #[must_use]
    pub fn camera(&self) -> prism_scene::Camera {
        let c = self.base;
        prism_scene::Camera {
            eye: self.orbit.eye(c.eye, c.target),
            ..c
        }
    }

    /// The render settings of a `w x h` pass.
    fn options(&self, w: u32, h: u32) -> RenderOptions {
        RenderOptions {
            width: w,
            height: h,
            spp: MAX_PASSES,
            only_bounce: self.only_bounce,
            seed: self.seed,
            ..RenderOptions::default()
        }
    }

    fn restart(&mut self) -> Response {
        self.sums = None;
        self.passes = 0;
        Response::Redraw
    }
}

impl Mode for PathMode {
    fn name(&self) -> &'static str {
        "path"
    }

    fn title(&self) -> String {
        format!("prism view: {} (path tracing)", self.path.display())
    }

    fn help(&self) -> Vec<(&'static str, &'static str)> {
        vec![
            ("drag", "orbit the camera about its target (restarts)"),
            ("wheel", "move the camera closer or farther (restarts)"),
            ("1-9", "only the m-th bounce of light (restarts)"),
            ("0", "every bounce (restarts)"),
            (
                "A",
                "noise heat map: red where adaptive sampling would go on",
            ),
            ("R", "reset the camera (restarts)"),
        ]
    }

    fn input(&mut self, input: &Input, size: (u32, u32)) -> Response {
        match *input {
            Input::Key { key, ctrl: false } => match key {
                Key::Char(c @ '1'..='9') => {
                    self.only_bounce = c.to_digit(10);
                    self.restart()
                }
                Key::Char('0') => {
                    self.only_bounce = None;
                    self.restart()
                }
                Key::Char('a') => {
                    self.heatmap = !self.heatmap;
                    Response::Redraw
                }
                Key::Char('r') => {
                    self.orbit.reset();
                    self.restart()
                }
                _ => Response::Ignored,
            },
            Input::Cursor { x, y } => {
                if self.orbit.cursor(x, y, size.0) {
                    self.restart()
                } else {
                    Response::Ignored
                }
            }
            Input::Button(down) => {
                self.orbit.button(down);
                Response::Ignored
            }
            Input::Wheel(lines) => {
                self.orbit.wheel(lines);
                self.restart()
            }
            Input::Resize { .. } => self.restart(),
            Input::Key { .. } => Response::Ignored,
        }
    }

    fn draw(&mut self, width: u32, height: u32) -> Rgb8Image {
        let fresh = self
            .sums
            .as_ref()
            .is_none_or(|s| (s.width(), s.height()) != (width, height));
        if fresh {
            self.sums = Some(Image::new(width, height, PixelSum::default()));
            self.passes = 0;
        }
        if self.passes < MAX_PASSES {
            self.scene.camera = self.camera();
            let opts = self.options(width, height);
            let share = Share {
                part: 0,
                parts: 1,
                samples: self.passes..self.passes + 1,
            };
            let t = Instant::now();
            let pass = render_share(&self.scene, &opts, &share, &|_| {});
            let secs = t.elapsed().as_secs_f64();
            self.rate = f64::from(width) * f64::from(height) / secs.max(1e-9);
            let sums = self.sums.as_mut().expect("made above");
            for (acc, add) in sums.pixels_mut().iter_mut().zip(pass.pixels()) {
                acc.merge(add);
            }
            self.passes += 1;
        }
        let sums = self.sums.as_ref().expect("made above");
        if self.heatmap {
            sums.map(|s| heat_colour(noise(s)))
        } else {
            sums.map(PixelSum::mean).linear_to_srgb8()
        }
    }

    fn status(&self) -> String {
        let bounces = self
            .only_bounce
            .map_or("all bounces".to_string(), |m| format!("bounce {m} only"));
        format!(
            "{} spp | {:.2} M samples/s | {bounces}{}",
            self.passes,
            self.rate / 1e6,
            if self.heatmap { " | noise map" } else { "" }
        )
    }

    fn busy(&self) -> bool {
        self.passes < MAX_PASSES
    }
}

/// The 95% confidence half-width of a pixel's illuminance relative to its mean, as adaptive
/// sampling judges it, scaled so that 1 is a tolerance of 5% or worse.
fn noise(s: &PixelSum) -> f32 {
    if s.n < 2 {
        return 1.0;
    }
    let n = f64::from(s.n);
    let mean = s.moment1 / n;
    let var = ((s.moment2 - s.moment1 * s.moment1 / n) / (n - 1.0)).max(0.0);
    let interval = 1.96 * (var / n).sqrt();
    if mean <= 0.0 {
        return if interval > 0.0 { 1.0 } else { 0.0 };
    }
    ((interval / mean) / 0.05) as f32
}
