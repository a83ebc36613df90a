//! Images in documents: decoding an image file or `data:` URI into a texture once per
//! reference, and the standard `<image>` element placed by its `preserveAspectRatio`.

use std::path::{Path as FsPath, PathBuf};
use std::sync::Arc;

use base64::Engine;
use prism_image::{Texture, UvConvention};
use roxmltree::Node;

use super::common::{number_with_unit, ElementAt, PlainAttribute, SvgError};
use super::context::Ctx;
use super::number::Precision;
use crate::document::{Document, Item, Mat3};

/// Decodes an image file or `data:` URI into a texture and registers it.
pub(crate) fn load_texture(
    ctx: &Ctx,
    doc: &mut Document,
    href: &str,
    loc: &ElementAt,
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

/// An `<image>` element as an [`Item::Image`]; `None` when it has no size.
pub(crate) fn image_item(
    node: &Node,
    transform: Mat3,
    ctx: &Ctx,
    doc: &mut Document,
    loc: &ElementAt,
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
        sampling: prism_image::PixelSampling::Bilinear,
    }))
}
