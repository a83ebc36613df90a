//! [`WhittedMode`]: the Delft ray tracer with its visual debugging in the window: feature
//! switches as keys, a click on a pixel traces its ray tree (coloured as `prism raytrace
//! --debug-pixel` colours it) and keeps it in the scene while the camera orbits, and the BVH
//! shown level by level and leaf by leaf. While the camera moves, frames are traced at half
//! the width and height; once it rests, at full resolution.

use std::time::{Duration, Instant};

use prism_image::{Bloom, Rgb8Image, RgbImage};
use prism_render::whitted::camera::OrbitView;
use prism_render::whitted::film::{raytrace, trace_pixel, PixelTrace, RaytraceOptions};
use prism_render::whitted::overlay::Overlay;
use prism_render::whitted::scene::{Environment, SceneSetup, Split, WhittedScene};
use prism_render::whitted::tracer::WhittedSettings;
use prism_scene::{Extras, Features, OrbitCamera, Scene};

use crate::input::{Input, Key};
use crate::viewer::{Mode, Response};

/// The keys of the feature switches, in the order of [`Features::NAMES`].
const KEYS: [char; 17] = [
    '1', '2', '3', '4', '5', '6', '7', '8', '9', '0', 'm', 'd', 'b', 'g', 'e', 'p', 'a',
];

/// A Whitted scene in the viewer.
pub struct WhittedMode {
    name: String,
    source: Scene,
    scene: WhittedScene,
    start: OrbitCamera,
    camera: OrbitCamera,
    features: Features,
    base: Option<RgbImage>,
    trace: Option<PixelTrace>,
    level: Option<usize>,
    leaf: Option<usize>,
    cursor: (f64, f64),
    press: Option<(f64, f64)>,
    last: (f64, f64),
    /// The camera moved since the last full-resolution picture: the next one is a preview.
    moving: bool,
    /// The picture is a preview (half width and height, scaled up) still to be refined.
    preview: bool,
    /// When the camera last moved.
    moved_at: Instant,
    /// How long the camera must rest before the picture is refined.
    rest: Duration,
    /// The extras' settings.
    extras: Extras,
    /// The moving meshes (index, translation over the shutter).
    motion: Vec<(usize, prism_math::Vec3)>,
    /// The environment map.
    environment: Option<std::sync::Arc<RgbImage>>,
}

/// How long the camera rests before a preview is traced again at full resolution.
pub const REST: Duration = Duration::from_millis(150);

impl WhittedMode {
    /// A viewer of `scene` (named `name`) through `camera`, with `features` on.
    #[must_use]
    pub fn new(scene: Scene, name: &str, camera: OrbitCamera, features: Features) -> WhittedMode {
        let mut mode = WhittedMode {
            name: name.to_string(),
            // Replaced below, once the mode can say how to prepare it.
            scene: WhittedScene::new(&Scene::new(scene.camera), false),
            source: scene,
            start: camera,
            camera,
            features,
            base: None,
            trace: None,
            level: None,
            leaf: None,
            cursor: (0.0, 0.0),
            press: None,
            last: (0.0, 0.0),
            moving: false,
            preview: false,
            moved_at: Instant::now(),
            rest: REST,
            extras: Extras::default(),
            motion: Vec::new(),
            environment: None,
        };
        mode.scene = mode.prepare();
        mode
    }

    /// The mode with a config's extras: their settings, the meshes that move and the
    /// environment map (each used when its feature is on).
    #[must_use]
    pub fn with_extras(
        mut self,
        extras: Extras,
        motion: Vec<(usize, prism_math::Vec3)>,
        environment: Option<std::sync::Arc<RgbImage>>,
    ) -> WhittedMode {
        self.extras = extras;
        self.motion = motion;
        self.environment = environment;
        self.scene = self.prepare();
        self
    }

    /// The scene as the features say: BVH on or off (split by SAH or at the median), the
    /// moving meshes with motion blur on, the environment map with environment mapping on.
    fn prepare(&self) -> WhittedScene {
        let f = self.features;
        let split = if f.sah_binning {
            Split::Sah
        } else {
            Split::Median
        };
        WhittedScene::prepare(
            &self.source,
            SceneSetup {
                bvh: f.accel_structure.then_some(split),
                motion: if f.motion_blur {
                    self.motion.clone()
                } else {
                    Vec::new()
                },
                environment: (self.environment.as_ref())
                    .filter(|_| f.environment_mapping)
                    .map(|im| Environment::new((**im).clone(), self.extras.environment_strength)),
            },
        )
    }

    /// The mode with another rest before refining (zero refines at the next frame).
    #[must_use]
    pub fn with_rest(mut self, rest: Duration) -> WhittedMode {
        self.rest = rest;
        self
    }

    /// True while the picture is a half-resolution preview.
    #[must_use]
    pub fn previewing(&self) -> bool {
        self.preview
    }

    /// The ray tree of the pixel clicked last.
    #[must_use]
    pub fn trace(&self) -> Option<&PixelTrace> {
        self.trace.as_ref()
    }

    /// The camera now.
    #[must_use]
    pub fn camera(&self) -> OrbitCamera {
        self.camera
    }

    fn options(&self, width: u32, height: u32) -> RaytraceOptions {
        RaytraceOptions {
            width,
            height,
            settings: WhittedSettings {
                features: self.features,
                light_samples: 16,
                max_depth: 3,
                extras: self.extras,
            },
            spp: 16,
            bloom: Bloom::default(),
            seed: 0,
        }
    }

    fn changed(&mut self) -> Response {
        self.base = None;
        self.moving = false;
        Response::Redraw
    }

    /// The camera moved: the next picture is a preview.
    fn moved(&mut self) -> Response {
        self.base = None;
        self.moving = true;
        self.moved_at = Instant::now();
        Response::Redraw
    }
}

impl Mode for WhittedMode {
    fn name(&self) -> &'static str {
        "whitted"
    }

    fn title(&self) -> String {
        format!("prism view: {} (Whitted ray tracer)", self.name)
    }

    fn help(&self) -> Vec<(&'static str, &'static str)> {
        vec![
            ("click", "trace the pixel's rays and keep them in the scene"),
            ("X", "clear the rays"),
            ("drag", "orbit the camera (half resolution until it rests)"),
            ("wheel", "move the camera closer or farther"),
            (
                "1-9 0 M",
                "shading, recursive, hard/soft shadow, normal interp,",
            ),
            (
                "",
                "texture, bilinear, bvh, bloom, transparency, multi-rays",
            ),
            (
                "D B G E P A",
                "depth of field, motion blur, glossy, environment map,",
            ),
            ("", "mip-mapping, SAH binning (off: median split)"),
            ("[ ]", "BVH level down / up (below 0: none)"),
            (", .", "BVH leaf back / forward (below 0: none)"),
            ("R", "reset the camera"),
        ]
    }

    fn input(&mut self, input: &Input, size: (u32, u32)) -> Response {
        match *input {
            Input::Key { key, ctrl: false } => match key {
                Key::Char(c) if KEYS.contains(&c) => {
                    let i = KEYS.iter().position(|&k| k == c).expect("found");
                    let name = Features::NAMES[i];
                    let on = self.features.switch(name).expect("a switch's name");
                    *on = !*on;
                    let state = if *on { "on" } else { "off" };
                    // These change the scene: its BVH, what moves, what misses see.
                    if matches!(name, "bvh" | "sah" | "motion-blur" | "env-map") {
                        self.scene = self.prepare();
                    }
                    if matches!(name, "bvh" | "sah") {
                        self.level = None;
                        self.leaf = None;
                    }
                    self.changed();
                    Response::Message(format!("{name} {state}"))
                }
                Key::Char('x') => {
                    self.trace = None;
                    Response::Redraw
                }
                Key::Char('r') => {
                    self.camera = self.start;
                    self.changed()
                }
                Key::Char(c @ ('[' | ']' | ',' | '.')) => {
                    let Some(bvh) = self.scene.bvh() else {
                        return Response::Message("the BVH is off (8 turns it on)".into());
                    };
                    let (slot, count) = match c {
                        '[' | ']' => (&mut self.level, bvh.levels()),
                        _ => (&mut self.leaf, bvh.leaf_views().len()),
                    };
                    *slot = match (c, *slot) {
                        (']' | '.', None) if count > 0 => Some(0),
                        (']' | '.', Some(k)) => Some((k + 1).min(count.saturating_sub(1))),
                        ('[' | ',', Some(0)) | ('[' | ',', None) => None,
                        ('[' | ',', Some(k)) => Some(k - 1),
                        (_, s) => s,
                    };
                    Response::Redraw
                }
                _ => Response::Ignored,
            },
            Input::Cursor { x, y } => {
                self.cursor = (x, y);
                if self.press.is_none() {
                    return Response::Ignored;
                }
                let per_pixel = 180.0 / size.0.max(1) as f32;
                let (dx, dy) = ((x - self.last.0) as f32, (y - self.last.1) as f32);
                self.last = (x, y);
                self.camera.rotation.y -= dx * per_pixel;
                self.camera.rotation.x =
                    (self.camera.rotation.x + dy * per_pixel).clamp(-89.0, 89.0);
                self.moved()
            }
            Input::Button(true) => {
                self.press = Some(self.cursor);
                self.last = self.cursor;
                Response::Ignored
            }
            Input::Button(false) => {
                let Some((px, py)) = self.press.take() else {
                    return Response::Ignored;
                };
                let (x, y) = self.cursor;
                if (x - px).abs() > 2.0 || (y - py).abs() > 2.0 {
                    return Response::Ignored;
                }
                // A click: the pixel under the cursor, traced from the camera as it is now.
                let (cx, cy) = (x.floor(), y.floor());
                if cx < 0.0 || cy < 0.0 || cx >= f64::from(size.0) || cy >= f64::from(size.1) {
                    return Response::Ignored;
                }
                let opts = self.options(size.0, size.1);
                let t = trace_pixel(&self.scene, &self.camera, &opts, cx as u32, cy as u32);
                let n = t.rays.len();
                self.trace = Some(t);
                Response::Message(format!("pixel ({cx}, {cy}): {n} rays"))
            }
            Input::Wheel(lines) => {
                self.camera.distance =
                    (self.camera.distance * 0.9f32.powf(lines as f32)).clamp(1e-3, 1e6);
                self.moved()
            }
            Input::Resize { .. } => self.changed(),
            Input::Key { .. } => Response::Ignored,
        }
    }

    fn draw(&mut self, width: u32, height: u32) -> Rgb8Image {
        let stale = self
            .base
            .as_ref()
            .is_none_or(|b| (b.width(), b.height()) != (width, height));
        let rested = self.preview && self.moved_at.elapsed() >= self.rest;
        if stale && self.moving {
            // A preview: half the width and height, each pixel drawn as a 2 x 2 block.
            let (w, h) = (width.div_ceil(2), height.div_ceil(2));
            let opts = self.options(w, h);
            let small = raytrace(&self.scene, &self.camera, &opts, &|_| {}).image;
            self.base = Some(RgbImage::from_fn(width, height, |x, y| {
                small.get(x / 2, y / 2)
            }));
            self.moving = false;
            self.preview = true;
        } else if stale || rested {
            let opts = self.options(width, height);
            self.base = Some(raytrace(&self.scene, &self.camera, &opts, &|_| {}).image);
            self.preview = false;
        }
        let base = self.base.as_ref().expect("drawn above");
        if self.trace.is_none() && self.level.is_none() && self.leaf.is_none() {
            return base.to_rgb8_truncated();
        }
        // The picture is dimmed under rays so that they stand out.
        let under = if self.trace.is_some() {
            base.map(|p| *p * 0.5)
        } else {
            base.clone()
        };
        let mut ov = Overlay::new(
            under,
            OrbitView::new(&self.camera, width, height),
            &self.scene,
        );
        if let Some(t) = &self.trace {
            ov.ray_tree(&t.rays);
        }
        ov.bvh(&self.scene, self.level, self.leaf);
        ov.image.to_rgb8_truncated()
    }

    fn busy(&self) -> bool {
        self.preview
    }

    fn status(&self) -> String {
        let mut f = self.features;
        let on: Vec<&str> = Features::NAMES
            .into_iter()
            .filter(|name| f.switch(name).is_some_and(|on| *on))
            .collect();
        let show = |v: Option<usize>| v.map_or("-".to_string(), |k| k.to_string());
        format!(
            "{} | BVH level {} leaf {}",
            on.join(" "),
            show(self.level),
            show(self.leaf)
        )
    }
}
