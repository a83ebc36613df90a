//! [`SvgMode`]: the course rasterizer viewer's controls over prism's SVG rasterizer: the
//! sample rate (`-`/`=`: 1, 4, 9, 16), pixel and level sampling (`P`, `L`), drag to pan,
//! wheel to zoom about the cursor, `R` to reset the view and `S` to save a screenshot.

use std::path::{Path, PathBuf};

use prism_image::{LevelSampling, PixelSampling, Rgb8Image};
use prism_raster::{render, Dialect, Document, RasterOptions, View};

use crate::input::{Input, Key};
use crate::viewer::{Mode, Response};

/// The sample rates `-` and `=` step through.
const RATES: [u32; 4] = [1, 4, 9, 16];

/// An SVG document in the viewer.
pub struct SvgMode {
    path: PathBuf,
    doc: Document,
    compat: bool,
    samples: u32,
    pixel: PixelSampling,
    level: LevelSampling,
    /// The visible region, `(cx, cy, span)` in viewport units; `None` until the first
    /// frame fits the drawing to the window.
    view: Option<(f64, f64, f64)>,
    cursor: (f64, f64),
    drag: Option<(f64, f64)>,
    screenshots: PathBuf,
    last: Option<Rgb8Image>,
}

impl SvgMode {
    /// A viewer of `doc`, read from `path` in `dialect`; screenshots go to the folder
    /// `screenshots`.
    #[must_use]
    pub fn new(doc: Document, path: &Path, dialect: Dialect, screenshots: &Path) -> SvgMode {
        SvgMode {
            path: path.to_path_buf(),
            doc,
            compat: dialect == Dialect::Cs184,
            samples: 1,
            pixel: PixelSampling::Nearest,
            level: LevelSampling::Zero,
            view: None,
            cursor: (0.0, 0.0),
            drag: None,
            screenshots: screenshots.to_path_buf(),
            last: None,
        }
    }

    /// Samples per pixel.
    #[must_use]
    pub fn samples(&self) -> u32 {
        self.samples
    }

    /// The visible region `(cx, cy, span)`, once drawn.
    #[must_use]
    pub fn region(&self) -> Option<(f64, f64, f64)> {
        self.view
    }

    /// The region showing the whole drawing in a `w x h` window: the course's view (1.2
    /// times the larger side across) for its dialect, else the viewport with 5% to spare.
    fn fit(&self, w: u32, h: u32) -> (f64, f64, f64) {
        let (dw, dh) = (self.doc.width, self.doc.height);
        let (w, h) = (f64::from(w), f64::from(h));
        let m = w.min(h);
        let span = if self.compat {
            0.6 * dw.max(dh)
        } else {
            1.05 * (dw * m / (2.0 * w)).max(dh * m / (2.0 * h))
        };
        (dw / 2.0, dh / 2.0, span.max(1e-9))
    }

    /// Pixels per viewport unit in a `w x h` window.
    fn scale(span: f64, (w, h): (u32, u32)) -> f64 {
        f64::from(w.min(h)) / (2.0 * span)
    }

    fn screenshot(&mut self, size: (u32, u32)) -> Response {
        let picture = match &self.last {
            Some(p) => p.clone(),
            None => self.draw(size.0, size.1),
        };
        let stem = self
            .path
            .file_stem()
            .map_or("svg".into(), |s| s.to_string_lossy().into_owned());
        let mut n = 1;
        let path = loop {
            let p = self.screenshots.join(format!("{stem}-screenshot-{n}.png"));
            if !p.exists() {
                break p;
            }
            n += 1;
        };
        match prism_image::write_png(&path, &picture) {
            Ok(()) => Response::Message(format!("saved {}", path.display())),
            Err(e) => Response::Message(format!("screenshot not saved: {e}")),
        }
    }
}

impl Mode for SvgMode {
    fn name(&self) -> &'static str {
        "svg"
    }

    fn title(&self) -> String {
        format!("prism view: {}", self.path.display())
    }

    fn help(&self) -> Vec<(&'static str, &'static str)> {
        vec![
            ("- =", "fewer / more samples per pixel (1, 4, 9, 16)"),
            ("P", "pixel sampling: nearest / bilinear"),
            ("L", "level sampling: level 0 / nearest level / trilinear"),
            ("drag", "pan"),
            ("wheel", "zoom about the cursor"),
            ("R", "reset the view"),
            ("S", "save a screenshot PNG"),
        ]
    }

    fn input(&mut self, input: &Input, size: (u32, u32)) -> Response {
        match *input {
            Input::Key { key, ctrl: false } => match key {
                Key::Char('=' | '+') => {
                    let i = RATES.iter().position(|&r| r == self.samples).unwrap_or(0);
                    self.samples = RATES[(i + 1).min(RATES.len() - 1)];
                    Response::Redraw
                }
                Key::Char('-') => {
                    let i = RATES.iter().position(|&r| r == self.samples).unwrap_or(0);
                    self.samples = RATES[i.saturating_sub(1)];
                    Response::Redraw
                }
                Key::Char('p') => {
                    self.pixel = match self.pixel {
                        PixelSampling::Nearest => PixelSampling::Bilinear,
                        PixelSampling::Bilinear | PixelSampling::Bicubic => PixelSampling::Nearest,
                    };
                    Response::Redraw
                }
                Key::Char('l') => {
                    self.level = match self.level {
                        LevelSampling::Zero => LevelSampling::Nearest,
                        LevelSampling::Nearest => LevelSampling::Linear,
                        LevelSampling::Linear => LevelSampling::Zero,
                    };
                    Response::Redraw
                }
                Key::Char('r') => {
                    self.view = Some(self.fit(size.0, size.1));
                    Response::Redraw
                }
                Key::Char('s') => self.screenshot(size),
                _ => Response::Ignored,
            },
            Input::Cursor { x, y } => {
                self.cursor = (x, y);
                let (Some((px, py)), Some((cx, cy, span))) = (self.drag, self.view) else {
                    return Response::Ignored;
                };
                let s = Self::scale(span, size);
                self.view = Some((cx - (x - px) / s, cy - (y - py) / s, span));
                self.drag = Some((x, y));
                Response::Redraw
            }
            Input::Button(down) => {
                self.drag = down.then_some(self.cursor);
                Response::Ignored
            }
            Input::Wheel(lines) => {
                let (cx, cy, span) = self.view.unwrap_or_else(|| self.fit(size.0, size.1));
                let s = Self::scale(span, size);
                let (w, h) = (f64::from(size.0), f64::from(size.1));
                // The point under the cursor stays there.
                let (ox, oy) = (self.cursor.0 - w / 2.0, self.cursor.1 - h / 2.0);
                let (ux, uy) = (cx + ox / s, cy + oy / s);
                let new_span = (span * 1.25f64.powf(-lines)).clamp(1e-6, 1e9);
                let s2 = Self::scale(new_span, size);
                self.view = Some((ux - ox / s2, uy - oy / s2, new_span));
                Response::Redraw
            }
            Input::Resize { .. } | Input::Key { .. } => Response::Ignored,
        }
    }

    fn draw(&mut self, width: u32, height: u32) -> Rgb8Image {
        let (cx, cy, span) = match self.view {
            Some(v) => v,
            None => {
                let f = self.fit(width, height);
                self.view = Some(f);
                f
            }
        };
        let opts = RasterOptions {
            width,
            height,
            samples: self.samples,
            pixel_sampling: self.pixel,
            level_sampling: self.level,
            view: View::Region { cx, cy, span },
            compat: self.compat,
        };
        let picture = match render(&self.doc, &opts) {
            Ok((image, _)) if self.compat => image.to_rgb8(),
            Ok((image, _)) => image.over_background([255, 255, 255]),
            // The window's size is within the rasterizer's limits; anything else shows grey.
            Err(_) => Rgb8Image::new(width, height, [128, 128, 128]),
        };
        self.last = Some(picture.clone());
        picture
    }

    fn status(&self) -> String {
        let pixel = match self.pixel {
            PixelSampling::Nearest => "nearest",
            PixelSampling::Bilinear => "bilinear",
            PixelSampling::Bicubic => "bicubic",
        };
        let level = match self.level {
            LevelSampling::Zero => "level 0",
            LevelSampling::Nearest => "nearest level",
            LevelSampling::Linear => "trilinear",
        };
        format!("{} spp | pixel {pixel} | {level}", self.samples)
    }
}
