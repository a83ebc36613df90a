//! [`Viewer`]: one [`Mode`] behind the controls every mode shares (`H` help overlay, `Esc`
//! quit), the status line, and the frame composed from the mode's picture and the overlays.

use prism_image::Rgb8Image;

use crate::input::{Input, Key};
use crate::text::{draw_text, GLYPH};

/// What a mode did with an input.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Response {
    /// Nothing changed.
    Ignored,
    /// The picture must be drawn again.
    Redraw,
    /// Something to tell the user on the status line (an invalid operation says why, a
    /// screenshot says where it went); the picture is drawn again too.
    Message(String),
}

/// One kind of file in the viewer: its state, its controls and its picture.
pub trait Mode {
    /// The mode's name (`svg`, ...).
    fn name(&self) -> &'static str;
    /// The window title.
    fn title(&self) -> String;
    /// The mode's controls as `(keys, what they do)`, for the help overlay and `--help`.
    fn help(&self) -> Vec<(&'static str, &'static str)>;
    /// Handles one input; `size` is the window's.
    fn input(&mut self, input: &Input, size: (u32, u32)) -> Response;
    /// The picture at `width x height`, without overlays.
    fn draw(&mut self, width: u32, height: u32) -> Rgb8Image;
    /// The state in one line, for the status bar (and for tests).
    fn status(&self) -> String;
    /// True while the mode wants more frames without input (progressive rendering).
    fn busy(&self) -> bool {
        false
    }
}

/// A composed frame and how long its picture took.
#[derive(Clone, Debug)]
pub struct Frame {
    /// The pixels: the picture, the status line and the help overlay if shown.
    pub image: Rgb8Image,
    /// Milliseconds the mode took to draw the picture.
    pub millis: f64,
}

/// The viewer: a mode, the window size, and the overlays.
pub struct Viewer {
    mode: Box<dyn Mode>,
    size: (u32, u32),
    help: bool,
    message: Option<String>,
    picture: Option<Rgb8Image>,
    millis: f64,
    quit: bool,
}

/// The status bar's height in pixels.
const STATUS: u32 = GLYPH + 6;

impl Viewer {
    /// A viewer of `mode` in a `width x height` window.
    #[must_use]
    pub fn new(mode: Box<dyn Mode>, width: u32, height: u32) -> Viewer {
        Viewer {
            mode,
            size: (width.max(1), height.max(1)),
            help: false,
            message: None,
            picture: None,
            millis: 0.0,
            quit: false,
        }
    }

    /// The mode.
    #[must_use]
    pub fn mode(&self) -> &dyn Mode {
        self.mode.as_ref()
    }

    /// The window size.
    #[must_use]
    pub fn size(&self) -> (u32, u32) {
        self.size
    }

    /// The window title.
    #[must_use]
    pub fn title(&self) -> String {
        self.mode.title()
    }

    /// True once the user asked to quit (`Esc`).
    #[must_use]
    pub fn quit(&self) -> bool {
        self.quit
    }

    /// True while the help overlay is shown.
    #[must_use]
    pub fn help_shown(&self) -> bool {
        self.help
    }

    /// The last message shown on the status line.
    #[must_use]
    pub fn message(&self) -> Option<&str> {
        self.message.as_deref()
    }

    /// True while the mode wants frames without input.
    #[must_use]
    pub fn busy(&self) -> bool {
        self.mode.busy()
    }

    /// Handles one input; returns true if the frame changed.
    pub fn input(&mut self, input: Input) -> bool {
        match input {
            Input::Key {
                key: Key::Escape, ..
            } => {
                self.quit = true;
                false
            }
            Input::Key {
                key: Key::Char('h'),
                ctrl: false,
            } => {
                self.help = !self.help;
                true
            }
            Input::Resize { width, height } => {
                self.size = (width.max(1), height.max(1));
                self.picture = None;
                self.mode.input(&input, self.size);
                true
            }
            _ => match self.mode.input(&input, self.size) {
                Response::Ignored => false,
                Response::Redraw => {
                    self.picture = None;
                    true
                }
                Response::Message(m) => {
                    self.message = Some(m);
                    self.picture = None;
                    true
                }
            },
        }
    }

    /// The mode's picture at the window size, without overlays (drawn if it changed).
    pub fn picture(&mut self) -> &Rgb8Image {
        if self.picture.is_none() || self.mode.busy() {
            let t = std::time::Instant::now();
            self.picture = Some(self.mode.draw(self.size.0, self.size.1));
            self.millis = t.elapsed().as_secs_f64() * 1e3;
        }
        self.picture.as_ref().expect("drawn above")
    }

    /// The frame: the picture, a status line at the bottom (the mode's state, the last
    /// message, the picture's time) and the help overlay when shown.
    pub fn frame(&mut self) -> Frame {
        let mut image = self.picture().clone();
        let (w, h) = (image.width(), image.height());
        let mut line = format!("{} | {:.1} ms | H: help", self.mode.status(), self.millis);
        if let Some(m) = &self.message {
            line = format!("{m} | {line}");
        }
        if h > STATUS {
            shade(&mut image, 0, h - STATUS, w, STATUS);
            draw_text(
                &mut image,
                4,
                i64::from(h - STATUS + 3),
                &line,
                1,
                [255, 255, 255],
            );
        }
        if self.help {
            let mut rows: Vec<(String, String)> = vec![
                ("H".into(), "show or hide this help".into()),
                ("Esc".into(), "quit".into()),
            ];
            rows.extend(
                self.mode
                    .help()
                    .into_iter()
                    .map(|(k, d)| (k.to_string(), d.to_string())),
            );
            let keys = rows.iter().map(|(k, _)| k.len()).max().unwrap_or(0);
            let longest = rows
                .iter()
                .map(|(_, d)| keys + 2 + d.len())
                .max()
                .unwrap_or(0) as u32;
            let (bw, bh) = ((longest + 2) * GLYPH, (rows.len() as u32 + 2) * (GLYPH + 4));
            shade(
                &mut image,
                8,
                8,
                bw.min(w.saturating_sub(8)),
                bh.min(h.saturating_sub(8)),
            );
            for (i, (k, d)) in rows.iter().enumerate() {
                let y = 8 + (i as u32 + 1) * (GLYPH + 4);
                let text = format!("{k:keys$}  {d}");
                draw_text(&mut image, 16, i64::from(y), &text, 1, [255, 255, 160]);
            }
        }
        Frame {
            image,
            millis: self.millis,
        }
    }
}

/// Darkens a rectangle to a third, so that text on it reads over any picture.
fn shade(image: &mut Rgb8Image, x0: u32, y0: u32, w: u32, h: u32) {
    for y in y0..(y0 + h).min(image.height()) {
        for x in x0..(x0 + w).min(image.width()) {
            let p = image.get(x, y);
            image.set(x, y, p.map(|c| c / 3));
        }
    }
}
