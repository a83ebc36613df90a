//! [`Input`], the events a viewer takes: what a window system reports, reduced to what the
//! modes need.

/// A key, by what it types (letters lower case) or by name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Key {
    /// A key that types this character (letters as lower case).
    Char(char),
    /// Escape.
    Escape,
    /// Left arrow.
    Left,
    /// Right arrow.
    Right,
    /// Up arrow.
    Up,
    /// Down arrow.
    Down,
}

/// An input event.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Input {
    /// A key was pressed, with or without Ctrl.
    Key {
        /// The key.
        key: Key,
        /// Ctrl was held.
        ctrl: bool,
    },
    /// The cursor moved to `(x, y)`, in pixels from the window's top-left corner.
    Cursor {
        /// Column.
        x: f64,
        /// Row.
        y: f64,
    },
    /// The left button went down (`true`) or up; a press and release without moving is a
    /// click.
    Button(bool),
    /// The wheel turned by this many lines (positive: away from the user, zoom in).
    Wheel(f64),
    /// The window's inner size changed.
    Resize {
        /// Width in pixels.
        width: u32,
        /// Height in pixels.
        height: u32,
    },
}
