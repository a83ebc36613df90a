//! The settings of one render: output size and sample-count limits, where the document is
//! placed ([`View`] and [`view_transform`]), the flattening tolerance, and [`RasterError`]
//! for settings outside the limits.

use prism_image::{LevelSampling, PixelSampling};

use crate::document::{Document, Mat3};

/// Largest output width or height in pixels.
pub const MAX_DIMENSION: u32 = 16_384;
/// Largest sample count per pixel (a 16 x 16 grid).
pub const MAX_SAMPLES: u32 = 256;

/// Curve flattening tolerance in output pixels.
pub(super) const TOLERANCE: f64 = 0.05;

/// How the document is placed in the output image.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum View {
    /// The document's viewport (after its `viewBox`) fills the output.
    #[default]
    Fit,
    /// The square region centred at `(cx, cy)` reaching `span` units to each side, centred
    /// in the output with uniform scale `min(width, height) / (2 span)`. Units are those of
    /// the document's viewport (its `width` and `height`, after any `viewBox` mapping),
    /// which for the course's files are the canvas units.
    Region {
        /// Centre x in viewport units.
        cx: f64,
        /// Centre y in viewport units.
        cy: f64,
        /// Half the side of the visible square, in viewport units.
        span: f64,
    },
}

/// Settings for one [`render`](super::render) of a document: output size, sampling and
/// placement.
#[derive(Clone, Debug, PartialEq)]
pub struct RasterOptions {
    /// Output width in pixels.
    pub width: u32,
    /// Output height in pixels.
    pub height: u32,
    /// Samples per pixel; a perfect square.
    pub samples: u32,
    /// Texel lookup for textured triangles.
    pub pixel_sampling: PixelSampling,
    /// Mip level selection for textured triangles.
    pub level_sampling: LevelSampling,
    /// Placement of the document.
    pub view: View,
    /// The course renderer's behaviour: opaque white background, all triangles with the
    /// inclusive edge rule, a one-pixel black canvas outline, truncating 8-bit conversion,
    /// and [`View::Fit`] meaning the course's view (centre of the canvas, 20% margin).
    pub compat: bool,
}

impl Default for RasterOptions {
    fn default() -> Self {
        RasterOptions {
            width: 1024,
            height: 1024,
            samples: 1,
            pixel_sampling: PixelSampling::Nearest,
            level_sampling: LevelSampling::Zero,
            view: View::Fit,
            compat: false,
        }
    }
}

/// Invalid render settings.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RasterError {
    /// Width or height outside `1..=MAX_DIMENSION`.
    #[error("output size {0}x{1} is outside 1..={MAX_DIMENSION} pixels per side")]
    BadSize(u32, u32),
    /// Sample count not a perfect square in `1..=MAX_SAMPLES`.
    #[error("samples per pixel must be a perfect square from 1 to {MAX_SAMPLES} (1, 4, 9, 16, ...), found {0}")]
    BadSamples(u32),
    /// The view region is not finite and positive.
    #[error("view span must be finite and positive, found centre ({0}, {1}) span {2}")]
    BadView(f64, f64, f64),
}

/// The sample rate `r` for `samples = r * r`, if it is a valid count.
#[must_use]
pub fn sample_rate(samples: u32) -> Option<u32> {
    let r = (f64::from(samples)).sqrt().round() as u32;
    ((1..=MAX_SAMPLES).contains(&samples) && r * r == samples).then_some(r)
}

/// The transform from document user space to output pixels for these options.
#[must_use]
pub fn view_transform(doc: &Document, opts: &RasterOptions) -> Mat3 {
    let region = match opts.view {
        View::Region { cx, cy, span } => Some((cx, cy, span)),
        View::Fit if opts.compat => {
            // The course's view: the canvas centre, 1.2 x the larger side across.
            let (w, h) = (doc.width as f32, doc.height as f32);
            let span = (1.2 * f64::from(w.max(h)) / 2.0) as f32;
            Some((f64::from(w / 2.0), f64::from(h / 2.0), f64::from(span)))
        }
        View::Fit => None,
    };
    match region {
        Some((cx, cy, span)) => {
            // Computed exactly as the course renderer does: NDC from a homogeneous
            // matrix with w = 2 span, then NDC to a centred square of the output.
            let (cx, cy, span) = (cx as f32, cy as f32, span as f32);
            let svg_to_ndc = Mat3([
                [1.0, 0.0, f64::from(span - cx)],
                [0.0, 1.0, f64::from(span - cy)],
                [0.0, 0.0, f64::from(2.0 * span)],
            ]);
            let (w, h) = (opts.width as f32, opts.height as f32);
            let s = w.min(h);
            let ndc_to_screen = Mat3([
                [f64::from(s), 0.0, f64::from((w - s) / 2.0)],
                [0.0, f64::from(s), f64::from((h - s) / 2.0)],
                [0.0, 0.0, 1.0],
            ]);
            let m = ndc_to_screen.mul(&svg_to_ndc);
            if opts.compat {
                m
            } else {
                m.mul(&doc.view_box_transform)
            }
        }
        None => Mat3::scale(
            f64::from(opts.width) / doc.width,
            f64::from(opts.height) / doc.height,
        )
        .mul(&doc.view_box_transform),
    }
}
