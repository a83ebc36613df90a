//! The plain document a reader produces and the rasterizer consumes: shapes with their
//! transforms and paints, no pixels and no parsing state.

use std::sync::Arc;

use prism_image::Texture;
use prism_math::{DVec2, Rgb, Vec2};

use crate::path::{Path, StrokeStyle};

/// A 3x3 homogeneous 2D transform in `f64`, row-major, mapping column vectors
/// `(x, y, 1)`; points are divided by the third component after mapping.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mat3(pub [[f64; 3]; 3]);

impl Default for Mat3 {
    fn default() -> Self {
        Mat3::IDENTITY
    }
}

impl Mat3 {
    /// The identity transform.
    pub const IDENTITY: Mat3 = Mat3([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);

    /// The SVG `matrix(a, b, c, d, e, f)`: `[[a, c, e], [b, d, f], [0, 0, 1]]`.
    #[must_use]
    pub fn affine(a: f64, b: f64, c: f64, d: f64, e: f64, f: f64) -> Mat3 {
        Mat3([[a, c, e], [b, d, f], [0.0, 0.0, 1.0]])
    }

    /// A translation.
    #[must_use]
    pub fn translate(x: f64, y: f64) -> Mat3 {
        Mat3::affine(1.0, 0.0, 0.0, 1.0, x, y)
    }

    /// A scale about the origin.
    #[must_use]
    pub fn scale(x: f64, y: f64) -> Mat3 {
        Mat3::affine(x, 0.0, 0.0, y, 0.0, 0.0)
    }

    /// A rotation by `deg` degrees, clockwise on a y-down screen (the SVG convention).
    #[must_use]
    pub fn rotate(deg: f64) -> Mat3 {
        let (s, c) = (deg * std::f64::consts::PI / 180.0).sin_cos();
        Mat3::affine(c, s, -s, c, 0.0, 0.0)
    }

    /// Skew along x by `deg` degrees.
    #[must_use]
    pub fn skew_x(deg: f64) -> Mat3 {
        Mat3::affine(
            1.0,
            0.0,
            (deg * std::f64::consts::PI / 180.0).tan(),
            1.0,
            0.0,
            0.0,
        )
    }

    /// Skew along y by `deg` degrees.
    #[must_use]
    pub fn skew_y(deg: f64) -> Mat3 {
        Mat3::affine(
            1.0,
            (deg * std::f64::consts::PI / 180.0).tan(),
            0.0,
            1.0,
            0.0,
            0.0,
        )
    }

    /// The product `self * rhs` (apply `rhs` first).
    #[must_use]
    pub fn mul(&self, rhs: &Mat3) -> Mat3 {
        let (a, b) = (&self.0, &rhs.0);
        let mut m = [[0.0; 3]; 3];
        for (i, row) in m.iter_mut().enumerate() {
            for (j, v) in row.iter_mut().enumerate() {
                *v = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
            }
        }
        Mat3(m)
    }

    /// Maps a point, dividing by the homogeneous coordinate.
    #[must_use]
    pub fn apply(&self, p: DVec2) -> DVec2 {
        let m = &self.0;
        let x = p.x * m[0][0] + p.y * m[0][1] + m[0][2];
        let y = p.x * m[1][0] + p.y * m[1][1] + m[1][2];
        let z = p.x * m[2][0] + p.y * m[2][1] + m[2][2];
        DVec2::new(x / z, y / z)
    }

    /// The affine part after normalising the homogeneous row, as `(linear 2x2, translation)`.
    /// Valid for transforms whose last row is `[0, 0, w]`.
    #[must_use]
    pub fn to_affine(&self) -> prism_math::DAffine2 {
        let m = &self.0;
        let w = m[2][2];
        prism_math::DAffine2::from_cols_array(&[
            m[0][0] / w,
            m[1][0] / w,
            m[0][1] / w,
            m[1][1] / w,
            m[0][2] / w,
            m[1][2] / w,
        ])
    }

    /// The largest factor by which the transform stretches a length.
    #[must_use]
    pub fn max_scale(&self) -> f64 {
        let a = self.to_affine();
        let (c0, c1) = (a.matrix2.x_axis, a.matrix2.y_axis);
        // Largest singular value of the 2x2 part.
        let (p, q, r) = (c0.length_squared(), c1.length_squared(), c0.dot(c1));
        let t = 0.5 * (p + q);
        let d = (0.25 * (p - q) * (p - q) + r * r).sqrt();
        (t + d).sqrt()
    }

    /// True if every entry is finite and the homogeneous scale is non-zero.
    #[must_use]
    pub fn is_valid(&self) -> bool {
        self.0.iter().flatten().all(|v| v.is_finite()) && self.0[2][2] != 0.0
    }
}

/// Which points a filled path covers.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FillRule {
    /// Inside where the winding number is non-zero.
    #[default]
    NonZero,
    /// Inside where the winding number is odd.
    EvenOdd,
}

/// One colour stop of a gradient.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stop {
    /// Position along the gradient in [0, 1].
    pub offset: f32,
    /// Colour at the stop (stored sRGB values, as in the file).
    pub color: Rgb,
    /// Opacity at the stop in [0, 1].
    pub opacity: f32,
}

/// How a gradient continues outside [0, 1].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Spread {
    /// Extend the end colours.
    #[default]
    Pad,
    /// Repeat the pattern.
    Repeat,
    /// Repeat, mirroring every other copy.
    Reflect,
}

/// The geometry of a gradient, in its own gradient space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum GradientKind {
    /// Colour varies along the line from `start` to `end`.
    Linear {
        /// Where offset 0 lies.
        start: DVec2,
        /// Where offset 1 lies.
        end: DVec2,
    },
    /// Colour varies with distance from `focus` to the circle (`center`, `radius`).
    Radial {
        /// Centre of the end circle.
        center: DVec2,
        /// Radius of the end circle.
        radius: f64,
        /// The focal point: centre of the start circle (offset 0).
        focus: DVec2,
        /// Radius of the start circle.
        focal_radius: f64,
    },
}

/// A linear or radial gradient paint.
#[derive(Clone, Debug, PartialEq)]
pub struct Gradient {
    /// Geometry.
    pub kind: GradientKind,
    /// Stops sorted by offset; at least one.
    pub stops: Vec<Stop>,
    /// Behaviour outside [0, 1].
    pub spread: Spread,
    /// Maps gradient space to the user space of the painted element.
    pub transform: Mat3,
}

/// What a fill or stroke is painted with.
#[derive(Clone, Debug, PartialEq)]
pub enum Paint {
    /// One colour (stored sRGB values in [0, 1]).
    Solid(Rgb),
    /// A gradient.
    Gradient(Arc<Gradient>),
    /// A tile of drawings repeated over the plane.
    Pattern(Arc<Pattern>),
}

/// A pattern paint: `items` drawn in a tile of `rect`, repeated.
#[derive(Clone, Debug)]
pub struct Pattern {
    /// The tile's content, in tile coordinates (origin at the tile's corner).
    pub items: Vec<Item>,
    /// The tile `(x, y, width, height)` in pattern space.
    pub rect: [f64; 4],
    /// Maps pattern space to the user space of the painted element.
    pub transform: Mat3,
}

impl PartialEq for Pattern {
    fn eq(&self, other: &Self) -> bool {
        std::ptr::eq(self, other)
    }
}

/// One drawable thing, in painter's order.
#[derive(Clone, Debug)]
pub enum Item {
    /// Triangles filled with one colour, each sample covered when it lies inside or on an
    /// edge (the course renderer's inclusive rule, used by `--compat cs184`).
    Triangles {
        /// Vertices in local coordinates.
        tris: Vec<[DVec2; 3]>,
        /// Local-to-document transform.
        transform: Mat3,
        /// Fill colour.
        color: Rgb,
    },
    /// A filled path.
    Fill {
        /// Geometry in local coordinates.
        path: Path,
        /// Local-to-document transform.
        transform: Mat3,
        /// Inside test.
        rule: FillRule,
        /// Paint.
        paint: Paint,
        /// Opacity in [0, 1].
        opacity: f32,
    },
    /// A stroked path.
    Stroke {
        /// Geometry in local coordinates.
        path: Path,
        /// Local-to-document transform.
        transform: Mat3,
        /// Width, joins, caps and dashes in local units.
        style: StrokeStyle,
        /// Paint.
        paint: Paint,
        /// Opacity in [0, 1].
        opacity: f32,
    },
    /// One-pixel lines through `points` drawn with the course's DDA: not antialiased, every
    /// sub-sample of a touched pixel takes the colour.
    Hairline {
        /// Vertices in local coordinates.
        points: Vec<DVec2>,
        /// Connect the last point back to the first.
        closed: bool,
        /// Local-to-document transform.
        transform: Mat3,
        /// Line colour.
        color: Rgb,
        /// Opacity in [0, 1] (the course renderer blends lines with `stroke-opacity`).
        opacity: f32,
    },
    /// A single pixel at `floor` of the transformed point, every sub-sample set.
    Point {
        /// Position in local coordinates.
        at: DVec2,
        /// Local-to-document transform.
        transform: Mat3,
        /// Colour.
        color: Rgb,
    },
    /// A triangle with per-vertex colours interpolated barycentrically.
    ColorTri {
        /// Vertices in local coordinates.
        points: [DVec2; 3],
        /// Vertex colours.
        colors: [Rgb; 3],
        /// Local-to-document transform.
        transform: Mat3,
    },
    /// A texture-mapped triangle.
    TexTri {
        /// Vertices in local coordinates.
        points: [DVec2; 3],
        /// Texture coordinates per vertex; (0, 0) is the top-left of the first row.
        uvs: [Vec2; 3],
        /// Index into [`Document::textures`].
        texture: usize,
        /// Local-to-document transform.
        transform: Mat3,
    },
    /// A raster image stretched over the rectangle `rect` = (x, y, width, height).
    Image {
        /// Index into [`Document::textures`].
        texture: usize,
        /// Placement in local coordinates.
        rect: [f64; 4],
        /// Local-to-document transform.
        transform: Mat3,
        /// Opacity in [0, 1].
        opacity: f32,
        /// Texel lookup (SVG's `image-rendering`).
        sampling: prism_image::PixelSampling,
    },
    /// Starts an offscreen layer, ended by the matching [`Item::EndLayer`],
    /// [`Item::ClipEnd`] or [`Item::MaskEnd`].
    BeginLayer,
    /// Ends the innermost layer and composites it onto what lies below.
    EndLayer {
        /// Group opacity in [0, 1].
        opacity: f32,
        /// How the layer's colours combine with those below.
        blend: BlendMode,
    },
    /// Ends the innermost layer, whose shapes are a clip path, and multiplies the layer
    /// below by its coverage (alpha): what lies outside the clip becomes transparent.
    ClipEnd,
    /// Ends the innermost layer, whose content is a mask, and multiplies the layer below by
    /// its luminance times alpha, or by its alpha alone.
    MaskEnd(MaskKind),
    /// A layer's content rendered whole, then passed through filters; drawn where it lies.
    Filtered(Arc<crate::filter::Filtered>),
}

/// Which value of a mask's content scales what it masks.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum MaskKind {
    /// `0.2125 R + 0.7154 G + 0.0721 B` of the stored sRGB values, times alpha (SVG's
    /// `mask-type: luminance`, with the coefficients resvg uses).
    #[default]
    Luminance,
    /// Alpha alone.
    Alpha,
}

/// How a layer's colours combine with the colours below it (CSS Compositing's
/// `mix-blend-mode`), on stored sRGB values with source-over alpha.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BlendMode {
    /// The source colour.
    #[default]
    Normal,
    /// `s * d`.
    Multiply,
    /// `s + d - s * d`.
    Screen,
    /// Hard light with source and backdrop swapped.
    Overlay,
    /// `min(s, d)`.
    Darken,
    /// `max(s, d)`.
    Lighten,
    /// Brightens the backdrop towards the source.
    ColorDodge,
    /// Darkens the backdrop towards the source.
    ColorBurn,
    /// Multiply or screen, by the source.
    HardLight,
    /// A softer hard light (the W3C formula).
    SoftLight,
    /// `|s - d|`.
    Difference,
    /// `s + d - 2 s d`.
    Exclusion,
    /// The source's hue with the backdrop's saturation and luminosity.
    Hue,
    /// The source's saturation with the backdrop's hue and luminosity.
    Saturation,
    /// The source's hue and saturation with the backdrop's luminosity.
    Color,
    /// The source's luminosity with the backdrop's hue and saturation.
    Luminosity,
    /// `min(1, s + d)` on premultiplied values.
    PlusLighter,
}

/// A parsed SVG, ready to rasterize.
#[derive(Clone, Debug, Default)]
pub struct Document {
    /// Viewport width in user units (the course's canvas width).
    pub width: f64,
    /// Viewport height in user units.
    pub height: f64,
    /// Maps user space to viewport space (the `viewBox` and `preserveAspectRatio` mapping;
    /// identity without a viewBox).
    pub view_box_transform: Mat3,
    /// Drawables in painter's order.
    pub items: Vec<Item>,
    /// Textures referenced by index from items. Colours of images with transparency are
    /// stored premultiplied by their alpha.
    pub textures: Vec<Arc<Texture>>,
    /// For each texture, its alpha channel (in the red channel) when the image has
    /// transparency that is drawn (`<image>` in standard SVG); `None` when opaque or when
    /// alpha is dropped (the course's `<texture>`).
    pub texture_alpha: Vec<Option<Arc<Texture>>>,
    /// One line per kind of thing that was skipped or approximated.
    pub warnings: Vec<prism_math::Warning>,
}

impl BlendMode {
    /// usvg's blend mode as prism's.
    #[must_use]
    pub fn from_usvg(b: usvg::BlendMode) -> BlendMode {
        use usvg::BlendMode as U;
        match b {
            U::Normal => BlendMode::Normal,
            U::Multiply => BlendMode::Multiply,
            U::Screen => BlendMode::Screen,
            U::Overlay => BlendMode::Overlay,
            U::Darken => BlendMode::Darken,
            U::Lighten => BlendMode::Lighten,
            U::ColorDodge => BlendMode::ColorDodge,
            U::ColorBurn => BlendMode::ColorBurn,
            U::HardLight => BlendMode::HardLight,
            U::SoftLight => BlendMode::SoftLight,
            U::Difference => BlendMode::Difference,
            U::Exclusion => BlendMode::Exclusion,
            U::Hue => BlendMode::Hue,
            U::Saturation => BlendMode::Saturation,
            U::Color => BlendMode::Color,
            U::Luminosity => BlendMode::Luminosity,
            U::PlusLighter => BlendMode::PlusLighter,
        }
    }
}

impl Document {
    /// The picture's size in pixels, as resvg's command line picks it: the document's own
    /// size in whole pixels (rounded up) times `zoom`; with only `width` or `height` the
    /// other follows the aspect ratio of that size, rounded up; with both, the document is
    /// fitted into that box keeping its aspect ratio (rounded).
    #[must_use]
    pub fn output_size(&self, width: Option<u32>, height: Option<u32>, zoom: f64) -> (u32, u32) {
        let aspect = self.width / self.height;
        let round = |v: f64| (v.round().max(1.0)).min(f64::from(u32::MAX)) as u32;
        let ceil = |v: f64| (v.ceil().max(1.0)).min(f64::from(u32::MAX)) as u32;
        let (iw, ih) = (self.width.ceil().max(1.0), self.height.ceil().max(1.0));
        match (width, height) {
            (Some(w), Some(h)) => {
                if f64::from(w) / f64::from(h) > aspect {
                    (round(f64::from(h) * aspect), h)
                } else {
                    (w, round(f64::from(w) / aspect))
                }
            }
            (Some(w), None) => (w, ceil(f64::from(w) * ih / iw)),
            (None, Some(h)) => (ceil(f64::from(h) * iw / ih), h),
            (None, None) => (ceil(self.width * zoom), ceil(self.height * zoom)),
        }
    }
}
