//! SVG readers: the standard dialect ([`Dialect::Svg`]) and the course's
//! ([`Dialect::Cs184`]), both producing a [`Document`].

mod color;
pub(crate) mod common;
pub(crate) mod cs184;
mod pathdata;
mod svg;

use std::path::{Path as FsPath, PathBuf};
use std::sync::Arc;

use base64::Engine;
use prism_image::{Texture, UvConvention};
use roxmltree::Node;

use common::{number_list, number_with_unit, Loc, PlainAttribute, Precision};
pub use common::{SvgError, MAX_DEPTH, MAX_HREF_CHAIN, MAX_ITEMS, MAX_SVG_BYTES, MAX_USE_ELEMENTS};
pub use pathdata::{parse_path_data, parse_path_data_prefix, PathDataError};

use std::collections::HashMap;

use prism_math::{DVec2, Rgb, Vec2};

use crate::document::{Document, Item, Mat3};

/// Which reading of SVG to apply.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Dialect {
    /// The SVG 1.1/2 specification's reading (what resvg and browsers do).
    #[default]
    Svg,
    /// The CS184 course renderer's reading, quirks included (see `FORMATS.md` section 1).
    Cs184,
}

/// Where a document came from, for resolving relative files and naming errors.
#[derive(Clone, Debug, Default)]
pub struct Source {
    /// The name used in error messages (usually the file path).
    pub name: String,
    /// The directory relative file references are resolved against.
    pub base_dir: PathBuf,
}

pub(crate) struct Ctx<'a> {
    pub source: &'a Source,
    pub xml: &'a roxmltree::Document<'a>,
    /// Line numbers of the text's byte offsets, for locating elements.
    pub lines: prism_math::LineIndex<'a>,
    pub warned: std::collections::BTreeSet<String>,
    /// Textures already decoded, by reference and uv convention: each file or data URI is
    /// decoded once however often it is used.
    pub textures: std::cell::RefCell<std::collections::HashMap<(String, UvConvention), usize>>,
}

impl Ctx<'_> {
    pub fn warn_once(&mut self, doc: &mut Document, key: &str, message: String) {
        if self.warned.insert(key.to_string()) {
            doc.warnings.push(message);
        }
    }
}

pub(crate) fn element_loc<'a>(ctx: &Ctx<'a>, node: &Node<'a, 'a>) -> Loc<'a> {
    let source: &'a Source = ctx.source;
    Loc {
        file: &source.name,
        line: ctx.lines.line(node.range().start),
        element: node.tag_name().name(),
    }
}

/// Decodes an image file or `data:` URI into a texture and registers it.
pub(crate) fn load_texture(
    ctx: &Ctx,
    doc: &mut Document,
    href: &str,
    loc: &Loc,
    uv: UvConvention,
) -> Result<usize, SvgError> {
    let key = (href.to_string(), uv);
    if let Some(&i) = ctx.textures.borrow().get(&key) {
        return Ok(i);
    }
    let rgba = if let Some(data) = href.trim().strip_prefix("data:") {
        let comma = data
            .find(',')
            .ok_or_else(|| loc.err("href: expected a data URI with a ',' before its payload"))?;
        let meta = &data[..comma];
        if !meta.ends_with(";base64") {
            return Err(loc.err("href: expected a base64 data URI"));
        }
        let payload: String = data[comma + 1..]
            .chars()
            .filter(|c| !c.is_whitespace())
            .collect();
        let bytes = base64::engine::general_purpose::STANDARD
            .decode(payload.as_bytes())
            .map_err(|e| loc.err(format!("href: invalid base64 image data: {e}")))?;
        let what = format!("{}:{}: embedded image", loc.file, loc.line);
        if bytes.starts_with(&[0xff, 0xd8]) {
            prism_image::decode_jpeg(&bytes, &what)
        } else {
            prism_image::decode_png(&bytes, &what)
        }
        .map_err(|e| loc.err(e.to_string()))?
    } else {
        let path: PathBuf = ctx.source.base_dir.join(FsPath::new(href));
        prism_image::read_image(&path).map_err(|e| loc.err(format!("texture {href:?}: {e}")))?
    };
    // Images keep their alpha (premultiplied, so filtering never bleeds hidden colours);
    // the course's textures drop it.
    let keep_alpha = uv == UvConvention::Standard && rgba.pixels().iter().any(|p| p[3] < 255);
    let (rgb, alpha) = if keep_alpha {
        let rgb = rgba.map(|p| {
            let a = f32::from(p[3]) / 255.0;
            prism_math::Rgb::from_u8([p[0], p[1], p[2]]) * a
        });
        let a = rgba.map(|p| prism_math::Rgb::splat(f32::from(p[3]) / 255.0));
        (rgb, Some(Arc::new(Texture::new(a).with_uv_convention(uv))))
    } else {
        (rgba.to_rgb8().to_rgb_f32(), None)
    };
    doc.textures
        .push(Arc::new(Texture::new(rgb).with_uv_convention(uv)));
    doc.texture_alpha.push(alpha);
    ctx.textures
        .borrow_mut()
        .insert(key, doc.textures.len() - 1);
    Ok(doc.textures.len() - 1)
}

/// Exactly `n` numbers from attribute `attr`.
fn exact_numbers(
    node: &Node,
    attr: &str,
    n: usize,
    loc: &Loc,
    p: Precision,
) -> Result<Vec<f64>, SvgError> {
    let v = number_list(node.attr(attr).unwrap_or(""), p, loc, attr)?;
    if v.len() != n {
        return Err(loc.err(format!("{attr}: expected {n} numbers, found {}", v.len())));
    }
    Ok(v)
}

/// Reads one of the course's custom elements into `doc`: `colortri` (points and r g b a
/// colours per vertex), `texture` (registers an image file under `texid`, alpha dropped,
/// edge-centred uvs) and `textri` (points, uvs and a `texid`). Returns false for any other
/// element.
#[allow(clippy::too_many_arguments)]
pub(crate) fn course_element(
    node: &Node,
    name: &str,
    transform: Mat3,
    ctx: &Ctx,
    doc: &mut Document,
    textures: &mut HashMap<String, usize>,
    loc: &Loc,
    p: Precision,
) -> Result<bool, SvgError> {
    let tri = |v: &[f64]| {
        [
            DVec2::new(v[0], v[1]),
            DVec2::new(v[2], v[3]),
            DVec2::new(v[4], v[5]),
        ]
    };
    match name {
        "colortri" => {
            let points = tri(&exact_numbers(node, "points", 6, loc, p)?);
            let c = exact_numbers(node, "colors", 12, loc, p)?;
            let col =
                |i: usize| Rgb::new(c[4 * i] as f32, c[4 * i + 1] as f32, c[4 * i + 2] as f32);
            doc.items.push(Item::ColorTri {
                points,
                colors: [col(0), col(1), col(2)],
                transform,
            });
        }
        "texture" => {
            let id = node
                .attr("texid")
                .ok_or_else(|| loc.err("expected a texid attribute"))?;
            let file = node
                .attr("filename")
                .ok_or_else(|| loc.err("expected a filename attribute"))?;
            let idx = load_texture(ctx, doc, file, loc, UvConvention::EdgeCenters)?;
            textures.insert(id.to_string(), idx);
        }
        "textri" => {
            let points = tri(&exact_numbers(node, "points", 6, loc, p)?);
            let uv = exact_numbers(node, "uvs", 6, loc, p)?;
            let id = node.attr("texid").unwrap_or("");
            let texture = *textures.get(id).ok_or_else(|| {
                loc.err(format!(
                    "texid {id:?}: expected the id of an earlier <texture>"
                ))
            })?;
            let f = |i: usize| Vec2::new(uv[2 * i] as f32, uv[2 * i + 1] as f32);
            doc.items.push(Item::TexTri {
                points,
                uvs: [f(0), f(1), f(2)],
                texture,
                transform,
            });
        }
        _ => return Ok(false),
    }
    Ok(true)
}

/// An `<image>` element as an [`Item::Image`]; `None` when it has no size.
pub(crate) fn image_item(
    node: &Node,
    transform: Mat3,
    ctx: &Ctx,
    doc: &mut Document,
    loc: &Loc,
    p: Precision,
) -> Result<Option<Item>, SvgError> {
    let href = node
        .attribute(("http://www.w3.org/1999/xlink", "href"))
        .or_else(|| node.attr("href"))
        .ok_or_else(|| loc.err("expected an xlink:href attribute"))?;
    let num = |name: &str| -> Result<Option<f64>, SvgError> {
        node.attr(name)
            .map(|s| number_with_unit(s, p, loc, name).map(|v| v.0))
            .transpose()
    };
    let texture = load_texture(ctx, doc, href, loc, UvConvention::Standard)?;
    let (tw, th) = doc.textures[texture].size();
    let (x, y) = (num("x")?.unwrap_or(0.0), num("y")?.unwrap_or(0.0));
    let (mut w, mut h) = (num("width")?, num("height")?);
    // A missing dimension follows the image's aspect ratio.
    match (w, h) {
        (None, None) => (w, h) = (Some(f64::from(tw)), Some(f64::from(th))),
        (Some(w0), None) => h = Some(w0 * f64::from(th) / f64::from(tw)),
        (None, Some(h0)) => w = Some(h0 * f64::from(tw) / f64::from(th)),
        _ => {}
    }
    let (w, h) = (w.unwrap_or(0.0), h.unwrap_or(0.0));
    if w <= 0.0 || h <= 0.0 {
        return Ok(None);
    }
    // preserveAspectRatio: default xMidYMid meet; "none" stretches.
    let par = node.attr("preserveAspectRatio").unwrap_or("xMidYMid meet");
    let rect = if par.trim() == "none" {
        [x, y, w, h]
    } else {
        let s = (w / f64::from(tw)).min(h / f64::from(th));
        let (iw, ih) = (f64::from(tw) * s, f64::from(th) * s);
        [x + (w - iw) / 2.0, y + (h - ih) / 2.0, iw, ih]
    };
    Ok(Some(Item::Image {
        texture,
        rect,
        transform,
        opacity: 1.0,
    }))
}

/// Parses SVG text in the given dialect.
///
/// # Errors
/// [`SvgError`] naming the file, line and element: malformed XML, a root that is not
/// `<svg>`, bad numbers, colours or path data, non-finite coordinates, a missing or corrupt
/// texture, or a document beyond the documented limits ([`MAX_DEPTH`], [`MAX_SVG_BYTES`],
/// [`MAX_ITEMS`], [`MAX_USE_ELEMENTS`], [`MAX_HREF_CHAIN`]), each its own variant.
pub fn parse_svg(text: &str, dialect: Dialect, source: &Source) -> Result<Document, SvgError> {
    if text.len() as u64 > MAX_SVG_BYTES {
        return Err(SvgError::FileTooLarge {
            file: source.name.clone(),
            limit: MAX_SVG_BYTES,
        });
    }
    let opts = roxmltree::ParsingOptions {
        allow_dtd: true,
        nodes_limit: 50_000_000,
        ..Default::default()
    };
    let xml = roxmltree::Document::parse_with_options(text, opts).map_err(|e| SvgError::Xml {
        file: source.name.clone(),
        line: e.pos().row,
        source: e,
    })?;
    let root = xml.root_element();
    let mut ctx = Ctx {
        source,
        xml: &xml,
        lines: prism_math::LineIndex::new(text),
        warned: Default::default(),
        textures: Default::default(),
    };
    if root.tag_name().name() != "svg" {
        let loc = element_loc(&ctx, &root);
        return Err(loc.err("expected the root element to be <svg>"));
    }
    match dialect {
        Dialect::Cs184 => cs184::parse(root, &mut ctx),
        Dialect::Svg => svg::parse(root, &mut ctx),
    }
}

/// Reads and parses an SVG file; relative references resolve against its directory.
///
/// # Errors
/// As [`parse_svg`], plus an unreadable or non-UTF-8 file.
pub fn read_svg(path: &FsPath, dialect: Dialect) -> Result<Document, SvgError> {
    let name = path.display().to_string();
    let io = |e: std::io::Error| SvgError::Io {
        file: name.clone(),
        source: Arc::new(e),
    };
    let bytes = prism_math::limits::read_input(path, MAX_SVG_BYTES).map_err(io)?;
    let text = String::from_utf8(bytes).map_err(|e| SvgError::Encoding {
        file: name.clone(),
        source: e.utf8_error(),
    })?;
    let base_dir = path.parent().map(FsPath::to_path_buf).unwrap_or_default();
    let source = Source { name, base_dir };
    parse_svg(&text, dialect, &source)
}

#[cfg(test)]
mod tests;
