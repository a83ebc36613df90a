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

    /// The viewer with `message` on its status line from the first frame (why the file
    /// opened in this mode, say).
    #[must_use]
    pub fn with_message(mut self, message: String) -> Viewer {
        self.message = Some(message);
        self
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
    /// message, the picture's time; wrapped onto more rows when the window is narrow) and
    /// the help overlay when shown (its descriptions wrapped to the window's width).
    pub fn frame(&mut self) -> Frame {
        let mut image = self.picture().clone();
        let (w, h) = (image.width(), image.height());
        let mut line = format!("{} | {:.1} ms | H: help", self.mode.status(), self.millis);
        if let Some(m) = &self.message {
            line = format!("{m} | {line}");
        }
        let cols = (w.saturating_sub(8) / GLYPH).max(8) as usize;
        let rows = wrap(&line, cols);
        let bar = STATUS + (rows.len() as u32 - 1) * (GLYPH + 2);
        if h > bar {
            shade(&mut image, 0, h - bar, w, bar);
            for (i, row) in rows.iter().enumerate() {
                let y = h - bar + 3 + i as u32 * (GLYPH + 2);
                draw_text(&mut image, 4, i64::from(y), row, 1, [255, 255, 255]);
            }
        }
        if self.help {
            let mut entries: Vec<(String, String)> = vec![
                ("H".into(), "show or hide this help".into()),
                ("Esc".into(), "quit".into()),
            ];
            entries.extend(
                self.mode
                    .help()
                    .into_iter()
                    .map(|(k, d)| (k.to_string(), d.to_string())),
            );
            let keys = entries.iter().map(|(k, _)| k.len()).max().unwrap_or(0);
            // The box spans the window less 8 pixels each side; text starts 8 pixels in.
            let inner = (w.saturating_sub(32) / GLYPH) as usize;
            let desc_cols = inner.saturating_sub(keys + 2).max(12);
            let mut lines = Vec::new();
            for (k, d) in &entries {
                for (i, part) in wrap(d, desc_cols).into_iter().enumerate() {
                    let key = if i == 0 { k.as_str() } else { "" };
                    lines.push(format!("{key:keys$}  {part}"));
                }
            }
            let longest = lines.iter().map(String::len).max().unwrap_or(0) as u32;
            let (bw, bh) = (
                (longest + 2) * GLYPH,
                (lines.len() as u32 + 2) * (GLYPH + 4),
            );
            shade(
                &mut image,
                8,
                8,
                bw.min(w.saturating_sub(16)),
                bh.min(h.saturating_sub(8)),
            );
            for (i, text) in lines.iter().enumerate() {
                let y = 8 + (i as u32 + 1) * (GLYPH + 4);
                draw_text(&mut image, 16, i64::from(y), text, 1, [255, 255, 160]);
            }
        }
        Frame {
            image,
            millis: self.millis,
        }
    }
}

/// `text` broken into rows of at most `cols` characters, at spaces where it can (a word
/// longer than a row is cut); at least one row.
fn wrap(text: &str, cols: usize) -> Vec<String> {
    let cols = cols.max(1);
    let mut rows = vec![String::new()];
    for word in text.split(' ').filter(|w| !w.is_empty()) {
        let mut word: Vec<char> = word.chars().collect();
        loop {
            let row = rows.last_mut().expect("one row at least");
            let used = row.chars().count();
            let gap = usize::from(used > 0);
            if used + gap + word.len() <= cols {
                if gap == 1 {
                    row.push(' ');
                }
                row.extend(word.iter());
                break;
            }
            if used > 0 {
                rows.push(String::new());
                continue;
            }
            // A word longer than a row: as much as fits, the rest on the next row.
            let rest = word.split_off(cols);
            row.extend(word.iter());
            rows.push(String::new());
            word = rest;
        }
    }
    if rows.len() > 1 && rows.last().is_some_and(String::is_empty) {
        rows.pop();
    }
    rows
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

#[cfg(test)]
mod tests {
    use super::wrap;

    /// Property: every row fits, no word is lost, and words are cut only when longer than a
    /// row.
    #[test]
    fn wrapped_rows_fit_and_keep_every_word() {
        let text = "mesh mode: a MeshEdit file | 12.5 ms | H: help averyveryverylongword x";
        for cols in [4, 8, 16, 30, 200] {
            let rows = wrap(text, cols);
            assert!(
                rows.iter().all(|r| r.chars().count() <= cols),
                "{cols}: {rows:?}"
            );
            let joined: String = rows.concat().chars().filter(|c| *c != ' ').collect();
            let want: String = text.chars().filter(|c| *c != ' ').collect();
            assert_eq!(joined, want, "{cols}");
        }
        assert_eq!(wrap("a b c", 200), vec!["a b c"]);
        assert_eq!(wrap("", 10), vec![""]);
    }
}
