//! Showing a CPU-drawn picture in an X11 window with Xlib's `XPutImage`. libX11 is loaded
//! when the first window opens, so no other command loads it.

use std::ffi::c_char;
use std::ptr;

use winit::raw_window_handle::{
    HandleError, HasDisplayHandle, HasWindowHandle, RawDisplayHandle, RawWindowHandle,
};
use winit::window::Window;
use x11_dl::xlib;

/// Why a window cannot show pictures.
#[derive(Debug, thiserror::Error)]
pub enum PresentError {
    /// The window system gave no handle.
    #[error("no window handle: {0}")]
    Handle(#[from] HandleError),
    /// The window is not an Xlib window.
    #[error("the window is not an X11 window")]
    NotX11,
    /// libX11 could not be loaded.
    #[error("cannot load libX11: {0}")]
    Xlib(String),
    /// The window's colour depth holds no 8-bit RGB.
    #[error("the window has a colour depth of {0} bits; 24 or 32 are needed")]
    Depth(i32),
    /// A graphics context or image could not be made.
    #[error("Xlib could not make its {0}")]
    Resource(&'static str),
}

/// A window's picture, shown through Xlib.
pub struct Presenter {
    xlib: xlib::Xlib,
    display: *mut xlib::Display,
    window: xlib::Window,
    gc: xlib::GC,
    visual: *mut xlib::Visual,
    depth: u32,
    pixels: Vec<u32>,
}

impl Presenter {
    /// Prepares to draw into `window`, which must stay open while this lives.
    ///
    /// # Errors
    /// [`PresentError`] when the window is not an X11 window of 24 or 32 bits, or Xlib
    /// fails.
    pub fn new(window: &Window) -> Result<Presenter, PresentError> {
        let display = match window.display_handle()?.as_raw() {
            RawDisplayHandle::Xlib(h) => h.display.ok_or(PresentError::NotX11)?.as_ptr(),
            _ => return Err(PresentError::NotX11),
        }
        .cast::<xlib::Display>();
        let win = match window.window_handle()?.as_raw() {
            RawWindowHandle::Xlib(h) => h.window,
            _ => return Err(PresentError::NotX11),
        };
        let xlib = xlib::Xlib::open().map_err(|e| PresentError::Xlib(e.to_string()))?;
        // SAFETY: `display` and `win` come from the live window; the attributes are
        // written by Xlib before they are read.
        let (visual, depth, gc) = unsafe {
            let mut attrs: xlib::XWindowAttributes = std::mem::zeroed();
            if (xlib.XGetWindowAttributes)(display, win, &mut attrs) == 0 {
                return Err(PresentError::Resource("window attributes"));
            }
            if attrs.depth != 24 && attrs.depth != 32 {
                return Err(PresentError::Depth(attrs.depth));
            }
            let gc = (xlib.XCreateGC)(display, win, 0, ptr::null_mut());
            if gc.is_null() {
                return Err(PresentError::Resource("graphics context"));
            }
            (attrs.visual, attrs.depth as u32, gc)
        };
        Ok(Presenter {
            xlib,
            display,
            window: win,
            gc,
            visual,
            depth,
            pixels: Vec::new(),
        })
    }

    /// Shows `rgb`, a `width x height` picture of 8-bit RGB pixels row by row, at the
    /// window's top left.
    ///
    /// # Errors
    /// [`PresentError::Resource`] if Xlib cannot make the image.
    pub fn show(
        &mut self,
        rgb: impl Iterator<Item = [u8; 3]>,
        width: u32,
        height: u32,
    ) -> Result<(), PresentError> {
        self.pixels.clear();
        self.pixels
            .extend(rgb.map(|p| u32::from(p[0]) << 16 | u32::from(p[1]) << 8 | u32::from(p[2])));
        if self.pixels.len() != width as usize * height as usize || self.pixels.is_empty() {
            return Ok(());
        }
        // SAFETY: the image borrows `pixels` (width * height 32-bit words, as the ZPixmap
        // of 32 bits a pixel that XCreateImage describes) only until XDestroyImage, and its
        // data pointer is cleared first so that Xlib frees only the image itself.
        unsafe {
            let image = (self.xlib.XCreateImage)(
                self.display,
                self.visual,
                self.depth,
                xlib::ZPixmap,
                0,
                self.pixels.as_mut_ptr().cast::<c_char>(),
                width,
                height,
                32,
                0,
            );
            if image.is_null() {
                return Err(PresentError::Resource("image"));
            }
            // The words are in this machine's byte order; Xlib converts if the server's
            // differs.
            (*image).byte_order = if cfg!(target_endian = "little") {
                xlib::LSBFirst
            } else {
                xlib::MSBFirst
            };
            (self.xlib.XPutImage)(
                self.display,
                self.window,
                self.gc,
                image,
                0,
                0,
                0,
                0,
                width,
                height,
            );
            (*image).data = ptr::null_mut();
            (self.xlib.XDestroyImage)(image);
            (self.xlib.XFlush)(self.display);
        }
        Ok(())
    }
}

impl Drop for Presenter {
    fn drop(&mut self) {
        // SAFETY: the context was made on this display, which the window keeps open.
        unsafe {
            (self.xlib.XFreeGC)(self.display, self.gc);
        }
    }
}
