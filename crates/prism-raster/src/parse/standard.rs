//! The standard dialect: SVG read by usvg into its resolved tree (CSS, units, `use`,
//! markers, text as paths), then turned into a [`Document`] of prism's items and layers.

use std::sync::Arc;

use prism_image::PixelSampling;
use prism_math::{DVec2, Loc, Rgb, Warning};
use usvg::tiny_skia_path::PathSegment;

use super::caught::catching;
use super::common::{SvgError, MAX_ITEMS};
use super::context::Source;
use super::fonts::font_database;
use super::guard::check_nesting;
use crate::document::{
    BlendMode, Document, FillRule, Gradient, GradientKind, Item, MaskKind, Mat3, Paint, Pattern,
    Spread, Stop,
};
use crate::filter::Filtered;
use crate::path::{LineCap, LineJoin, Path, StrokeStyle};

/// Parses standard SVG text with usvg and converts its tree.
pub(crate) fn parse(text: &str, source: &Source) -> Result<Document, SvgError> {
    let xml = check_nesting(text, source)?;
    let has_text = xml
        .descendants()
        .any(|n| n.is_element() && n.tag_name().name() == "text");
    let mut opts = usvg::Options {
        resources_dir: Some(source.base_dir.clone()),
        image_href_resolver: super::resources::resolver(source),
        ..usvg::Options::default()
    };
    if let Some(family) = &source.fonts.family {
        opts.font_family.clone_from(family);
    }
    if has_text {
        opts.fontdb = font_database(&source.fonts)?;
    }
    let (tree, caught) = catching(|| usvg::Tree::from_xmltree(&xml, &opts));
    let tree = tree.map_err(|e| SvgError::Usvg {
        file: source.name.clone(),
        source: Arc::new(e),
    })?;
    let size = tree.size();
    let mut doc = Document {
        width: f64::from(size.width()),
        height: f64::from(size.height()),
        ..Document::default()
    };
    let mut conv = Converter {
        doc: &mut doc,
        source,
        items: 0,
        decoded: Vec::new(),
    };
    let mut items = Vec::new();
    conv.group_content(tree.root(), Mat3::IDENTITY, &mut items)?;
    doc.items = items;
    let read_past = caught.into_iter().map(|m| Warning {
        at: None,
        message: format!("{}: {m}", source.name),
    });
    doc.warnings.splice(0..0, read_past);
    Ok(doc)
}

/// The usvg transform `[sx kx tx; ky sy ty]` as a [`Mat3`].
pub(crate) fn mat(t: usvg::Transform) -> Mat3 {
    Mat3::affine(
        f64::from(t.sx),
        f64::from(t.ky),
        f64::from(t.kx),
        f64::from(t.sy),
        f64::from(t.tx),
        f64::from(t.ty),
    )
}

/// A usvg colour as stored sRGB values in [0, 1].
pub(crate) fn rgb(c: usvg::Color) -> Rgb {
    Rgb::from_u8([c.red, c.green, c.blue])
}

/// The usvg path as a prism path.
fn path_of(data: &usvg::tiny_skia_path::Path) -> Path {
    let mut p = Path::default();
    let mut cur = DVec2::ZERO;
    let pt = |q: usvg::tiny_skia_path::Point| DVec2::new(f64::from(q.x), f64::from(q.y));
    for seg in data.segments() {
        match seg {
            PathSegment::MoveTo(a) => {
                cur = pt(a);
                p.move_to(cur);
            }
            PathSegment::LineTo(a) => {
                cur = pt(a);
                p.line_to(cur);
            }
            PathSegment::QuadTo(c, a) => {
                p.quad_to(cur, pt(c), pt(a));
                cur = pt(a);
            }
            PathSegment::CubicTo(c1, c2, a) => {
                p.cubic_to(pt(c1), pt(c2), pt(a));
                cur = pt(a);
            }
            PathSegment::Close => p.close(),
        }
    }
    p
}

/// Converts one usvg tree into items, counting them against [`MAX_ITEMS`].
pub(crate) struct Converter<'a> {
    pub(crate) doc: &'a mut Document,
    pub(crate) source: &'a Source,
    pub(crate) items: usize,
    /// Images decoded so far, by their encoded bytes: each is decoded once however often
    /// the document holds it.
    pub(crate) decoded: Vec<(Arc<Vec<u8>>, usize)>,
}

impl Converter<'_> {
    fn push(&mut self, out: &mut Vec<Item>, item: Item) -> Result<(), SvgError> {
        self.items += 1;
        if self.items > MAX_ITEMS {
            return Err(SvgError::ItemsLimit {
                at: Loc::line(&self.source.name, 0),
                element: "svg".into(),
                limit: MAX_ITEMS,
            });
        }
        out.push(item);
        Ok(())
    }

    /// The children of `g` drawn under `m` (the transform of `g` itself not applied).
    pub(crate) fn group_content(
        &mut self,
        g: &usvg::Group,
        m: Mat3,
        out: &mut Vec<Item>,
    ) -> Result<(), SvgError> {
        for node in g.children() {
            match node {
                usvg::Node::Group(c) => self.group(c, m, out)?,
                usvg::Node::Path(p) => self.path(p, m, out)?,
                usvg::Node::Image(i) => self.image(i, m, out)?,
                usvg::Node::Text(t) => self.group(t.flattened(), m, out)?,
            }
        }
        Ok(())
    }

    /// A group: its transform, and a layer with filters, clip, mask, opacity and blending
    /// when it needs one.
    fn group(
        &mut self,
        g: &usvg::Group,
        parent: Mat3,
        out: &mut Vec<Item>,
    ) -> Result<(), SvgError> {
        let m = parent.mul(&mat(g.transform()));
        if !g.should_isolate() {
            return self.group_content(g, m, out);
        }
        self.push(out, Item::BeginLayer)?;
        if g.filters().is_empty() {
            self.group_content(g, m, out)?;
        } else {
            let mut inner = Vec::new();
            self.group_content(g, m, &mut inner)?;
            let mut images = Vec::new();
            for f in g.filters() {
                for prim in f.primitives() {
                    if let usvg::filter::Kind::Image(img) = prim.kind() {
                        let mut items = Vec::new();
                        self.group_content(img.root(), Mat3::IDENTITY, &mut items)?;
                        images.push(items);
                    }
                }
            }
            let region = g.filters_bounding_box().map(|r| {
                [
                    f64::from(r.x()),
                    f64::from(r.y()),
                    f64::from(r.width()),
                    f64::from(r.height()),
                ]
            });
            let Some(region) = region else {
                // An invalid filter region draws nothing, as resvg does.
                self.push(
                    out,
                    Item::EndLayer {
                        opacity: 0.0,
                        blend: BlendMode::Normal,
                    },
                )?;
                return Ok(());
            };
            let f = Filtered {
                items: inner,
                transform: m,
                region,
                filters: g.filters().to_vec(),
                images,
            };
            self.push(out, Item::Filtered(Arc::new(f)))?;
        }
        if let Some(clip) = g.clip_path() {
            self.clip(clip, m, out)?;
        }
        if let Some(mask) = g.mask() {
            self.mask(mask, m, out)?;
        }
        self.push(
            out,
            Item::EndLayer {
                opacity: g.opacity().get(),
                blend: BlendMode::from_usvg(g.blend_mode()),
            },
        )
    }

    /// A clip path as a clip layer (and its own clip path after it).
    fn clip(
        &mut self,
        clip: &usvg::ClipPath,
        m: Mat3,
        out: &mut Vec<Item>,
    ) -> Result<(), SvgError> {
        self.push(out, Item::BeginLayer)?;
        let cm = m.mul(&mat(clip.transform()));
        self.clip_content(clip.root(), cm, out)?;
        self.push(out, Item::ClipEnd)?;
        if let Some(inner) = clip.clip_path() {
            self.clip(inner, m, out)?;
        }
        Ok(())
    }

    /// A clip path's shapes, filled opaque with their clip rule.
    fn clip_content(
        &mut self,
        g: &usvg::Group,
        m: Mat3,
        out: &mut Vec<Item>,
    ) -> Result<(), SvgError> {
        for node in g.children() {
            match node {
                usvg::Node::Path(p) => {
                    let Some(fill) = p.fill() else { continue };
                    if !p.is_visible() || !has_area(p) {
                        continue;
                    }
                    let item = Item::Fill {
                        path: path_of(p.data()),
                        transform: m,
                        rule: fill_rule(fill.rule()),
                        paint: Paint::Solid(Rgb::new(0.0, 0.0, 0.0)),
                        opacity: 1.0,
                    };
                    self.push(out, item)?;
                }
                usvg::Node::Text(t) => {
                    let f = t.flattened();
                    self.clip_content(f, m.mul(&mat(f.transform())), out)?;
                }
                usvg::Node::Group(c) => {
                    let cm = m.mul(&mat(c.transform()));
                    if let Some(clip) = c.clip_path() {
                        self.push(out, Item::BeginLayer)?;
                        self.clip_content(c, cm, out)?;
                        self.clip(clip, cm, out)?;
                        self.push(
                            out,
                            Item::EndLayer {
                                opacity: 1.0,
                                blend: BlendMode::Normal,
                            },
                        )?;
                    } else {
                        self.clip_content(c, cm, out)?;
                    }
                }
                usvg::Node::Image(_) => {}
            }
        }
        Ok(())
    }

    /// A mask as a mask layer limited to its region (and its own mask after it).
    fn mask(&mut self, mask: &usvg::Mask, m: Mat3, out: &mut Vec<Item>) -> Result<(), SvgError> {
        self.push(out, Item::BeginLayer)?;
        self.group_content(mask.root(), m, out)?;
        let r = mask.rect();
        let rect = Path::polygon(
            &[
                DVec2::new(f64::from(r.left()), f64::from(r.top())),
                DVec2::new(f64::from(r.right()), f64::from(r.top())),
                DVec2::new(f64::from(r.right()), f64::from(r.bottom())),
                DVec2::new(f64::from(r.left()), f64::from(r.bottom())),
            ],
            true,
        );
        self.push(out, Item::BeginLayer)?;
        let item = Item::Fill {
            path: rect,
            transform: m,
            rule: FillRule::NonZero,
            paint: Paint::Solid(Rgb::new(0.0, 0.0, 0.0)),
            opacity: 1.0,
        };
        self.push(out, item)?;
        self.push(out, Item::ClipEnd)?;
        let kind = match mask.kind() {
            usvg::MaskType::Luminance => MaskKind::Luminance,
            usvg::MaskType::Alpha => MaskKind::Alpha,
        };
        self.push(out, Item::MaskEnd(kind))?;
        if let Some(inner) = mask.mask() {
            self.mask(inner, m, out)?;
        }
        Ok(())
    }

    fn path(&mut self, p: &usvg::Path, m: Mat3, out: &mut Vec<Item>) -> Result<(), SvgError> {
        if !p.is_visible() {
            return Ok(());
        }
        let geometry = path_of(p.data());
        let fill = |this: &mut Self, out: &mut Vec<Item>| -> Result<(), SvgError> {
            let Some(f) = p.fill() else { return Ok(()) };
            if !has_area(p) {
                return Ok(());
            }
            let Some(paint) = this.paint(f.paint())? else {
                return Ok(());
            };
            let item = Item::Fill {
                path: geometry.clone(),
                transform: m,
                rule: fill_rule(f.rule()),
                paint,
                opacity: f.opacity().get(),
            };
            this.push(out, item)
        };
        let stroke = |this: &mut Self, out: &mut Vec<Item>| -> Result<(), SvgError> {
            let Some(s) = p.stroke() else { return Ok(()) };
            let Some(paint) = this.paint(s.paint())? else {
                return Ok(());
            };
            let style = StrokeStyle {
                width: f64::from(s.width().get()),
                join: match s.linejoin() {
                    usvg::LineJoin::Miter | usvg::LineJoin::MiterClip => LineJoin::Miter,
                    usvg::LineJoin::Round => LineJoin::Round,
                    usvg::LineJoin::Bevel => LineJoin::Bevel,
                },
                cap: match s.linecap() {
                    usvg::LineCap::Butt => LineCap::Butt,
                    usvg::LineCap::Round => LineCap::Round,
                    usvg::LineCap::Square => LineCap::Square,
                },
                miter_limit: f64::from(s.miterlimit().get()),
                dashes: s
                    .dasharray()
                    .map(|d| d.iter().map(|&v| f64::from(v)).collect())
                    .unwrap_or_default(),
                dash_offset: f64::from(s.dashoffset()),
            };
            let item = Item::Stroke {
                path: geometry.clone(),
                transform: m,
                style,
                paint,
                opacity: s.opacity().get(),
            };
            this.push(out, item)
        };
        match p.paint_order() {
            usvg::PaintOrder::FillAndStroke => {
                fill(self, out)?;
                stroke(self, out)
            }
            usvg::PaintOrder::StrokeAndFill => {
                stroke(self, out)?;
                fill(self, out)
            }
        }
    }

    /// A usvg paint in prism's terms; `None` for a pattern that draws nothing.
    fn paint(&mut self, paint: &usvg::Paint) -> Result<Option<Paint>, SvgError> {
        let stops = |b: &usvg::BaseGradient| -> Vec<Stop> {
            b.stops()
                .iter()
                .map(|s| Stop {
                    offset: s.offset().get(),
                    color: rgb(s.color()),
                    opacity: s.opacity().get(),
                })
                .collect()
        };
        let spread = |b: &usvg::BaseGradient| match b.spread_method() {
            usvg::SpreadMethod::Pad => Spread::Pad,
            usvg::SpreadMethod::Reflect => Spread::Reflect,
            usvg::SpreadMethod::Repeat => Spread::Repeat,
        };
        let f = f64::from;
        Ok(Some(match paint {
            usvg::Paint::Color(c) => Paint::Solid(rgb(*c)),
            usvg::Paint::LinearGradient(g) => Paint::Gradient(Arc::new(Gradient {
                kind: GradientKind::Linear {
                    start: DVec2::new(f(g.x1()), f(g.y1())),
                    end: DVec2::new(f(g.x2()), f(g.y2())),
                },
                stops: stops(g),
                spread: spread(g),
                transform: mat(g.transform()),
            })),
            usvg::Paint::RadialGradient(g) => Paint::Gradient(Arc::new(Gradient {
                kind: GradientKind::Radial {
                    center: DVec2::new(f(g.cx()), f(g.cy())),
                    radius: f(g.r().get()),
                    focus: DVec2::new(f(g.fx()), f(g.fy())),
                    focal_radius: f(g.fr().get()),
                },
                stops: stops(g),
                spread: spread(g),
                transform: mat(g.transform()),
            })),
            usvg::Paint::Pattern(p) => {
                let mut items = Vec::new();
                self.group_content(p.root(), Mat3::IDENTITY, &mut items)?;
                if items.is_empty() {
                    return Ok(None);
                }
                let r = p.rect();
                Paint::Pattern(Arc::new(Pattern {
                    items,
                    rect: [f(r.x()), f(r.y()), f(r.width()), f(r.height())],
                    transform: mat(p.transform()),
                }))
            }
        }))
    }

    fn image(&mut self, img: &usvg::Image, m: Mat3, out: &mut Vec<Item>) -> Result<(), SvgError> {
        if !img.is_visible() {
            return Ok(());
        }
        match img.kind() {
            usvg::ImageKind::SVG(tree) => {
                self.push(out, Item::BeginLayer)?;
                self.group_content(tree.root(), m, out)?;
                self.push(
                    out,
                    Item::EndLayer {
                        opacity: 1.0,
                        blend: BlendMode::Normal,
                    },
                )
            }
            kind => {
                let Some(texture) = super::resources::raster_texture(
                    self.doc,
                    kind,
                    self.source,
                    &mut self.decoded,
                )?
                else {
                    return Ok(());
                };
                let (w, h) = self.doc.textures[texture].size();
                let item = Item::Image {
                    texture,
                    rect: [0.0, 0.0, f64::from(w), f64::from(h)],
                    transform: m,
                    opacity: 1.0,
                    sampling: match img.rendering_mode() {
                        usvg::ImageRendering::OptimizeSpeed
                        | usvg::ImageRendering::CrispEdges
                        | usvg::ImageRendering::Pixelated => PixelSampling::Nearest,
                        usvg::ImageRendering::Smooth => PixelSampling::Bilinear,
                        usvg::ImageRendering::OptimizeQuality
                        | usvg::ImageRendering::HighQuality => PixelSampling::Bicubic,
                    },
                };
                self.push(out, item)
            }
        }
    }
}

/// Whether a fill can cover anything: resvg skips paths whose bounds have no width or no
/// height, and a path of two points (a `<line>`) encloses nothing either.
fn has_area(p: &usvg::Path) -> bool {
    let b = p.data().bounds();
    b.width() > 0.0 && b.height() > 0.0 && p.data().points().len() > 2
}

fn fill_rule(r: usvg::FillRule) -> FillRule {
    match r {
        usvg::FillRule::NonZero => FillRule::NonZero,
        usvg::FillRule::EvenOdd => FillRule::EvenOdd,
    }
}
