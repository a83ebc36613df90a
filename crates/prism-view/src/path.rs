//! [`PathMode`]: a COLLADA scene path-traced progressively, one sample per pixel a frame, the
//! passes added with the film's exact pixel sums (so the picture after n passes is the
//! `prism render -s n` image); dragging orbits the camera and the wheel moves it closer, each
//! restarting the passes; `1`-`9` keep only the m-th bounce, `0` all of them; `A` turns on
//! adaptive sampling (a pixel stops once converged, by the course's rule checked every 32
//! samples) and shows its heat map of samples per pixel, `M` switches between the heat map
//! and the picture.

use std::path::{Path, PathBuf};
use std::time::Instant;

use prism_image::{heatmap, Image, Rgb8Image};
use prism_render::film::{FilmSettings, PixelSum, Share};
use prism_render::integrators::PathSettings;
use prism_render::render::{render_share, Job, RenderOptions};
use prism_render::render_scene::RenderScene;

use crate::input::{Input, Key};
use crate::orbit::Orbit;
use crate::viewer::{Mode, Response};

/// Passes after which the picture is left as it is.
pub const MAX_PASSES: u32 = 4096;
/// Adaptive sampling's tolerance and the samples between its checks (`prism render`'s
/// defaults: `--adaptive 0.05 --batch 32`).
const TOLERANCE: f32 = 0.05;
const BATCH: u32 = 32;

/// A path-traced scene in the viewer.
pub struct PathMode {
    path: PathBuf,
    scene: RenderScene,
    base: prism_scene::Camera,
    orbit: Orbit,
    only_bounce: Option<u32>,
    adaptive: bool,
    heatmap: bool,
    /// Pixels adaptive sampling has stopped.
    done: Vec<bool>,
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
            adaptive: false,
            heatmap: false,
            done: Vec::new(),
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

    /// Each pixel's sums so far.
    #[must_use]
    pub fn sums(&self) -> Option<&Image<PixelSum>> {
        self.sums.as_ref()
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
            film: FilmSettings {
                width: w,
                height: h,
                spp: MAX_PASSES,
                seed: self.seed,
                ..FilmSettings::default()
            },
            path: PathSettings {
                only_bounce: self.only_bounce,
                ..PathSettings::default()
            },
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
                "adaptive sampling on / off, shown as its heat map (restarts)",
            ),
            ("M", "heat map of samples per pixel / picture"),
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
                    self.adaptive = !self.adaptive;
                    self.heatmap = self.adaptive;
                    self.restart()
                }
                Key::Char('m') => {
                    self.heatmap = !self.heatmap;
                    Response::Redraw
                }
                Key::Char('r') => {
                    self.orbit.reset();
                    self.restart()
                }
                _ => Response::Ignored,
            },
            Input::Cursor { .. } | Input::Button(_) | Input::Wheel(_) => {
                if self.orbit.input(input, size.0) == Some(true) {
                    self.restart()
                } else {
                    Response::Ignored
                }
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
        if self.passes == 0 {
            self.done = vec![false; width as usize * height as usize];
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
            let skip = self.adaptive.then_some(self.done.as_slice());
            let job = Job {
                share: &share,
                skip,
                profile: None,
                stop: None,
                camera: None,
            };
            let pass = render_share(&self.scene, &opts, &job, &|_| {});
            let secs = t.elapsed().as_secs_f64();
            let taken: u64 = pass.pixels().iter().map(|p| u64::from(p.n)).sum();
            self.rate = taken as f64 / secs.max(1e-9);
            let sums = self.sums.as_mut().expect("made above");
            for (acc, add) in sums.pixels_mut().iter_mut().zip(pass.pixels()) {
                // Passes of a render never overflow the exact sums; a pixel that would keeps
                // the samples it has.
                let _ = acc.merge(add);
            }
            self.passes += 1;
            if self.adaptive && self.passes.is_multiple_of(BATCH) {
                for (d, s) in self.done.iter_mut().zip(sums.pixels()) {
                    *d = *d || s.within(TOLERANCE);
                }
            }
        }
        let sums = self.sums.as_ref().expect("made above");
        if self.heatmap {
            heatmap(&sums.map(|s| s.n))
        } else {
            sums.map(PixelSum::mean).linear_to_srgb8()
        }
    }

    fn status(&self) -> String {
        let bounces = self
            .only_bounce
            .map_or("all bounces".to_string(), |m| format!("bounce {m} only"));
        let stopped = self.done.iter().filter(|&&d| d).count();
        let adaptive = if self.adaptive {
            format!(
                " | adaptive: {:.1}% of pixels done",
                100.0 * stopped as f64 / self.done.len().max(1) as f64
            )
        } else {
            String::new()
        };
        format!(
            "{} spp | {:.2} M samples/s | {bounces}{adaptive}{}",
            self.passes,
            self.rate / 1e6,
            if self.heatmap { " | heat map" } else { "" }
        )
    }

    fn busy(&self) -> bool {
        self.passes < MAX_PASSES && !(self.adaptive && self.done.iter().all(|&d| d))
    }
}
