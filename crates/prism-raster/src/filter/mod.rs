//! SVG filters on pixels: a filtered layer's description ([`Filtered`]) and the filter
//! graph run over premultiplied RGBA images the size of the layer's region, primitive by
//! primitive (inputs, results by name, subregions, sRGB or linearRGB), as SVG 1.1 and the
//! Filter Effects module define them. The primitives' pixel work lives in `blur`, `ops`
//! (colour and compositing), `lighting` and `turbulence`.

mod blur;
mod lighting;
mod ops;
mod turbulence;

use std::sync::Arc;

use prism_math::{DAffine2, DVec2};
use usvg::filter::{ColorInterpolation, Input, Kind};

use crate::document::{Item, Mat3};

/// A group drawn offscreen and passed through its filters.
#[derive(Clone, Debug)]
pub struct Filtered {
    /// The group's content, with transforms to document space.
    pub items: Vec<Item>,
    /// The group's user space to document space.
    pub transform: Mat3,
    /// The union of the filters' regions `(x, y, width, height)` in the group's user space.
    pub region: [f64; 4],
    /// The filters, applied in order.
    pub filters: Vec<Arc<usvg::filter::Filter>>,
    /// The content of each `feImage` primitive, in the order they appear, in the
    /// primitive's subregion space (origin at its corner, user units).
    pub images: Vec<Vec<Item>>,
}

/// Renders items through a view into a canvas-sized premultiplied image (how `feImage`
/// content is drawn, handed in by the rasterizer).
pub(crate) type DrawItems<'a> = dyn Fn(&[Item], &Mat3) -> Vec<[f32; 4]> + 'a;

/// An integer pixel rectangle `[x0, x1) x [y0, y1)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct IRect {
    pub x0: i32,
    pub y0: i32,
    pub x1: i32,
    pub y1: i32,
}

impl IRect {
    fn intersect(self, o: IRect) -> IRect {
        IRect {
            x0: self.x0.max(o.x0),
            y0: self.y0.max(o.y0),
            x1: self.x1.min(o.x1).max(self.x0.max(o.x0)),
            y1: self.y1.min(o.y1).max(self.y0.max(o.y0)),
        }
    }

    fn is_empty(self) -> bool {
        self.x1 <= self.x0 || self.y1 <= self.y0
    }

    /// The pixel box of a user-space rectangle under `ts` (floor of the start, the size
    /// rounded up, as tiny-skia's `to_int_rect`); `None` when not finite.
    fn of(r: [f64; 4], ts: &DAffine2) -> Option<IRect> {
        let [x, y, w, h] = r;
        let pts = [(x, y), (x + w, y), (x, y + h), (x + w, y + h)]
            .map(|(a, b)| ts.transform_point2(prism_math::DVec2::new(a, b)));
        let lo = pts.iter().fold(pts[0], |a, b| a.min(*b));
        let hi = pts.iter().fold(pts[0], |a, b| a.max(*b));
        if !(lo.is_finite() && hi.is_finite()) {
            return None;
        }
        let clamp = |v: f64| v.clamp(-1e9, 1e9) as i32;
        let (x0, y0) = (clamp(lo.x.floor()), clamp(lo.y.floor()));
        Some(IRect {
            x0,
            y0,
            x1: x0.saturating_add(clamp((hi.x - lo.x).ceil())),
            y1: y0.saturating_add(clamp((hi.y - lo.y).ceil())),
        })
    }
}

/// A premultiplied RGBA image the size of the canvas, with the rectangle that holds data
/// and the colour space its values are in. Pixels are shared between results and inputs
/// and copied only when a primitive changes a shared image.
#[derive(Clone, Debug)]
pub(crate) struct Img {
    pub w: usize,
    pub h: usize,
    pub px: Arc<Vec<[f32; 4]>>,
    pub region: IRect,
    pub linear: bool,
}

impl Img {
    fn empty(w: usize, h: usize, region: IRect) -> Img {
        Img {
            w,
            h,
            px: Arc::new(vec![[0.0; 4]; w * h]),
            region,
            linear: false,
        }
    }

    /// The image converted to linearRGB or sRGB as `cs` asks.
    fn into_space(mut self, cs: ColorInterpolation) -> Img {
        let want = cs == ColorInterpolation::LinearRGB;
        if want != self.linear {
            let f = if want {
                prism_image::srgb_to_linear
            } else {
                prism_image::linear_to_srgb
            };
            for p in Arc::make_mut(&mut self.px).iter_mut() {
                if p[3] > 0.0 {
                    for c in 0..3 {
                        p[c] = f((p[c] / p[3]).clamp(0.0, 1.0)) * p[3];
                    }
                }
            }
            self.linear = want;
        }
        self
    }

    /// Clears every pixel outside `r`.
    fn crop(&mut self, r: IRect) {
        let inside = IRect {
            x0: 0,
            y0: 0,
            x1: self.w as i32,
            y1: self.h as i32,
        };
        if r.intersect(inside) == inside {
            return;
        }
        let w = self.w;
        let px = Arc::make_mut(&mut self.px);
        for y in 0..self.h as i32 {
            let row = &mut px[y as usize * w..(y as usize + 1) * w];
            if y < r.y0 || y >= r.y1 {
                row.fill([0.0; 4]);
            } else {
                for (x, p) in row.iter_mut().enumerate() {
                    if (x as i32) < r.x0 || (x as i32) >= r.x1 {
                        *p = [0.0; 4];
                    }
                }
            }
        }
    }
}

/// The transform's scale as resvg takes it (tiny-skia's `get_scale`): the lengths of the
/// rows of its linear part, `(|(a, c)|, |(b, d)|)` for `x' = a x + c y`, `y' = b x + d y`.
/// Filter lengths (deviations, offsets, radii) are scaled by it.
pub(crate) fn scale_of(ts: &DAffine2) -> (f64, f64) {
    let m = ts.matrix2;
    (
        DVec2::new(m.x_axis.x, m.y_axis.x).length(),
        DVec2::new(m.x_axis.y, m.y_axis.y).length(),
    )
}

/// Runs `f`'s filters over `canvas` (a `w` x `h` premultiplied sRGB image whose pixel
/// `(0, 0)` is the device pixel the layer starts at); `ts` maps the group's user space to
/// canvas pixels, and `draw(items, view)` renders an `feImage`'s content into a canvas-sized
/// image.
pub(crate) fn apply(
    f: &Filtered,
    canvas: Vec<[f32; 4]>,
    w: usize,
    h: usize,
    ts: &DAffine2,
    draw: &DrawItems<'_>,
) -> Vec<[f32; 4]> {
    let full = IRect {
        x0: 0,
        y0: 0,
        x1: w as i32,
        y1: h as i32,
    };
    let mut source = Img {
        w,
        h,
        px: Arc::new(canvas),
        region: full,
        linear: false,
    };
    let mut image_index = 0;
    for filter in &f.filters {
        let r = filter.rect();
        let rect = [r.x(), r.y(), r.width(), r.height()].map(f64::from);
        let region = IRect::of(rect, ts).map(|r| r.intersect(full));
        let out = match region {
            Some(region) if !region.is_empty() => {
                // A filter that never reads its source (turbulence, flood, images) lets the
                // source's pixels go before it runs.
                let reads = filter.primitives().iter().any(|p| {
                    p.kind().has_input(&Input::SourceGraphic)
                        || p.kind().has_input(&Input::SourceAlpha)
                });
                if !reads {
                    source.px = Arc::new(Vec::new());
                }
                run(filter, &source, region, ts, draw, f, &mut image_index)
            }
            _ => None,
        };
        // A filter with an invalid region or no result leaves nothing, as in resvg.
        source = match out {
            Some(mut img) => {
                img = img.into_space(ColorInterpolation::SRGB);
                img.crop(region.unwrap_or(full));
                img.region = full;
                img
            }
            None => Img::empty(w, h, full),
        };
    }
    Arc::try_unwrap(source.px).unwrap_or_else(|shared| (*shared).clone())
}

/// One filter's graph; `None` when it has no primitives.
fn run(
    filter: &usvg::filter::Filter,
    source: &Img,
    region: IRect,
    ts: &DAffine2,
    draw: &DrawItems<'_>,
    f: &Filtered,
    image_index: &mut usize,
) -> Option<Img> {
    let (w, h) = (source.w, source.h);
    let mut results: Vec<(String, Img)> = Vec::new();
    let get = |input: &Input, results: &[(String, Img)]| -> Img {
        if source.px.is_empty() && !matches!(input, Input::Reference(_)) {
            return Img::empty(w, h, region);
        }
        match input {
            Input::SourceGraphic => Img {
                region,
                ..source.clone()
            },
            Input::SourceAlpha => Img {
                px: Arc::new(source.px.iter().map(|p| [0.0, 0.0, 0.0, p[3]]).collect()),
                region,
                ..source.clone()
            },
            Input::Reference(name) => results
                .iter()
                .rev()
                .find(|(n, _)| n == name)
                .map(|(_, i)| i.clone())
                .unwrap_or_else(|| {
                    if source.px.is_empty() {
                        Img::empty(w, h, region)
                    } else {
                        Img {
                            region,
                            ..source.clone()
                        }
                    }
                }),
        }
    };
    for (index, prim) in filter.primitives().iter().enumerate() {
        let r = prim.rect();
        let rect = [r.x(), r.y(), r.width(), r.height()].map(f64::from);
        let mut sub = IRect::of(rect, ts).unwrap_or(region);
        if let Kind::Offset(fe) = prim.kind() {
            if let Input::Reference(name) = fe.input() {
                if let Some((_, res)) = results.iter().rev().find(|(n, _)| n == name) {
                    sub = res.region;
                }
            }
        }
        let cs = prim.color_interpolation();
        let mut out = match prim.kind() {
            Kind::Blend(fe) => {
                let a = get(fe.input1(), &results).into_space(cs);
                let b = get(fe.input2(), &results).into_space(cs);
                ops::blend(&a, &b, crate::document::BlendMode::from_usvg(fe.mode()))
            }
            Kind::Composite(fe) => {
                let a = get(fe.input1(), &results).into_space(cs);
                let b = get(fe.input2(), &results).into_space(cs);
                ops::composite(&a, &b, fe.operator())
            }
            Kind::Merge(fe) => {
                let mut acc = Img::empty(w, h, region);
                acc.linear = cs == ColorInterpolation::LinearRGB;
                for input in fe.inputs() {
                    let i = get(input, &results).into_space(cs);
                    for (d, s) in Arc::make_mut(&mut acc.px).iter_mut().zip(i.px.iter()) {
                        crate::blend::over(d, *s);
                    }
                }
                acc
            }
            Kind::Flood(fe) => {
                let mut img = Img::empty(w, h, region);
                let c = fe.color();
                let c = prism_math::Rgb::from_u8([c.red, c.green, c.blue]);
                let a = fe.opacity().get();
                Arc::make_mut(&mut img.px).fill([c.r * a, c.g * a, c.b * a, a]);
                img
            }
            Kind::GaussianBlur(fe) => {
                let mut img = get(fe.input(), &results).into_space(cs);
                let (sx, sy) = scale_of(ts);
                let (dx, dy) = (
                    f64::from(fe.std_dev_x().get()) * sx,
                    f64::from(fe.std_dev_y().get()) * sy,
                );
                blur::gaussian(&mut img, dx, dy);
                img
            }
            Kind::DropShadow(fe) => {
                let input = get(fe.input(), &results).into_space(cs);
                let (sx, sy) = scale_of(ts);
                let mut shadow = input.clone();
                blur::gaussian(
                    &mut shadow,
                    f64::from(fe.std_dev_x().get()) * sx,
                    f64::from(fe.std_dev_y().get()) * sy,
                );
                let c = fe.color();
                let c = prism_math::Rgb::from_u8([c.red, c.green, c.blue]);
                let op = fe.opacity().get();
                let mut col = [c.r, c.g, c.b];
                if cs == ColorInterpolation::LinearRGB {
                    col = col.map(prism_image::srgb_to_linear);
                }
                for p in Arc::make_mut(&mut shadow.px).iter_mut() {
                    let a = p[3] * op;
                    *p = [col[0] * a, col[1] * a, col[2] * a, a];
                }
                let dx = (f64::from(fe.dx()) * sx) as i32;
                let dy = (f64::from(fe.dy()) * sy) as i32;
                let mut out = ops::offset(&shadow, dx, dy);
                for (d, s) in Arc::make_mut(&mut out.px).iter_mut().zip(input.px.iter()) {
                    crate::blend::over(d, *s);
                }
                out
            }
            Kind::Offset(fe) => {
                let input = get(fe.input(), &results);
                let (sx, sy) = scale_of(ts);
                let dx = (f64::from(fe.dx()) * sx) as i32;
                let dy = (f64::from(fe.dy()) * sy) as i32;
                ops::offset(&input, dx, dy)
            }
            Kind::Tile(fe) => ops::tile(&get(fe.input(), &results), region),
            Kind::Image(_) => {
                let (sx, sy) = scale_of(ts);
                let view =
                    Mat3::translate(f64::from(sub.x0), f64::from(sub.y0)).mul(&Mat3::scale(sx, sy));
                let items = f.images.get(*image_index).map_or(&[][..], Vec::as_slice);
                *image_index += 1;
                Img {
                    w,
                    h,
                    px: Arc::new(draw(items, &view)),
                    region,
                    linear: false,
                }
            }
            Kind::ComponentTransfer(fe) => {
                let mut img = get(fe.input(), &results).into_space(cs);
                ops::component_transfer(&mut img, fe);
                img
            }
            Kind::ColorMatrix(fe) => {
                let mut img = get(fe.input(), &results).into_space(cs);
                ops::color_matrix(&mut img, fe.kind());
                img
            }
            Kind::ConvolveMatrix(fe) => {
                let img = get(fe.input(), &results).into_space(cs);
                ops::convolve(&img, fe)
            }
            Kind::Morphology(fe) => {
                let img = get(fe.input(), &results).into_space(cs);
                let (sx, sy) = scale_of(ts);
                let rx = f64::from(fe.radius_x().get()) * sx;
                let ry = f64::from(fe.radius_y().get()) * sy;
                ops::morphology(img, fe.operator(), rx, ry)
            }
            Kind::DisplacementMap(fe) => {
                let a = get(fe.input1(), &results).into_space(cs);
                let b = get(fe.input2(), &results).into_space(cs);
                let (sx, sy) = scale_of(ts);
                ops::displace(&a, &b, fe, sx, sy)
            }
            Kind::Turbulence(fe) => {
                let mut img = Img::empty(w, h, region);
                turbulence::fill(&mut img, fe, ts, region);
                img.linear = cs == ColorInterpolation::LinearRGB;
                img
            }
            Kind::DiffuseLighting(fe) => {
                let input = get(fe.input(), &results);
                let mut img = lighting::diffuse(&input, fe, ts);
                img.linear = cs == ColorInterpolation::LinearRGB;
                img
            }
            Kind::SpecularLighting(fe) => {
                let input = get(fe.input(), &results);
                let mut img = lighting::specular(&input, fe, ts);
                img.linear = cs == ColorInterpolation::LinearRGB;
                img
            }
        };
        if sub != region {
            if !matches!(prim.kind(), Kind::Offset(_)) {
                out.crop(sub.intersect(region));
            }
            out.region = sub;
        } else {
            out.region = region;
        }
        results.push((prim.result().to_string(), out));
        // Results no later primitive reads are dropped: only the live ones hold memory.
        let later = &filter.primitives()[index + 1..];
        let last = results.len() - 1;
        let mut k = 0;
        results.retain(|(name, _)| {
            let keep = k == last
                || later
                    .iter()
                    .any(|p| p.kind().has_input(&Input::Reference(name.clone())));
            k += 1;
            keep
        });
    }
    results.pop().map(|(_, img)| img)
}
