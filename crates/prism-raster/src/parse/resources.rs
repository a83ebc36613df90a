//! Files a standard SVG links or embeds: the `href` resolver handed to usvg (regular files
//! only, within a size limit) and the decoding of raster images into textures.

use std::sync::Arc;

use prism_image::{Texture, UvConvention};
use prism_math::Warning;

use super::common::SvgError;
use super::context::Source;
use crate::document::Document;

/// The largest linked image file read, in bytes.
pub const MAX_IMAGE_BYTES: u64 = 256 << 20;

/// The kind of image `data` holds, by its first bytes (SVG when none matches).
fn kind_of(data: Vec<u8>, opts: &usvg::Options) -> Option<usvg::ImageKind> {
    let data = Arc::new(data);
    if data.starts_with(b"\x89PNG\r\n\x1a\n") {
        Some(usvg::ImageKind::PNG(data))
    } else if data.starts_with(&[0xff, 0xd8, 0xff]) {
        Some(usvg::ImageKind::JPEG(data))
    } else if data.starts_with(b"GIF8") {
        Some(usvg::ImageKind::GIF(data))
    } else if data.len() > 12 && &data[0..4] == b"RIFF" && &data[8..12] == b"WEBP" {
        Some(usvg::ImageKind::WEBP(data))
    } else {
        usvg::Tree::from_data_nested(&data, opts)
            .ok()
            .map(usvg::ImageKind::SVG)
    }
}

/// usvg's `href` resolver for `source`: linked files resolve against its directory and are
/// read only when they are regular files within [`MAX_IMAGE_BYTES`]; anything else is
/// skipped, as resvg skips an image it cannot load.
pub(crate) fn resolver(source: &Source) -> usvg::ImageHrefResolver<'static> {
    let base = source.base_dir.clone();
    usvg::ImageHrefResolver {
        resolve_data: Box::new(|_mime, data, opts| kind_of(data.to_vec(), opts)),
        resolve_string: Box::new(move |href, opts| {
            let path = base.join(href);
            let data = prism_math::limits::read_input(&path, MAX_IMAGE_BYTES).ok()?;
            kind_of(data, opts)
        }),
    }
}

/// Decodes a raster image into a texture of `doc` (colours premultiplied when it has
/// transparency); `None`, with a warning, when it cannot be decoded (the image is then
/// skipped, as resvg skips it).
///
/// # Errors
/// [`SvgError::Image`] for an image over the image budget: its size is refused before
/// its pixels are allocated.
pub(crate) fn raster_texture(
    doc: &mut Document,
    kind: &usvg::ImageKind,
    source: &Source,
    cache: &mut Vec<(Arc<Vec<u8>>, usize)>,
) -> Result<Option<usize>, SvgError> {
    let bytes = match kind {
        usvg::ImageKind::PNG(d)
        | usvg::ImageKind::JPEG(d)
        | usvg::ImageKind::GIF(d)
        | usvg::ImageKind::WEBP(d) => Some(d),
        usvg::ImageKind::SVG(_) => None,
    };
    if let Some(d) = bytes {
        if let Some((_, i)) = cache.iter().find(|(b, _)| Arc::ptr_eq(b, d) || b == d) {
            return Ok(Some(*i));
        }
    }
    let decoded = match kind {
        usvg::ImageKind::PNG(d) => prism_image::decode_png(d, "a PNG image it holds"),
        usvg::ImageKind::JPEG(d) => prism_image::decode_jpeg(d, "a JPEG image it holds"),
        usvg::ImageKind::GIF(d) => prism_image::decode_gif(d, "a GIF image it holds"),
        usvg::ImageKind::WEBP(d) => prism_image::decode_webp(d, "a WebP image it holds"),
        usvg::ImageKind::SVG(_) => return Ok(None),
    };
    let rgba = match decoded {
        Ok(i) => i,
        Err(e @ prism_image::ImageError::OverBudget { .. }) => {
            return Err(SvgError::Image {
                file: source.name.clone(),
                source: Arc::new(e),
            })
        }
        Err(e) => {
            warn(doc, format!("{}: an image was skipped: {e}", source.name));
            return Ok(None);
        }
    };
    let alpha = rgba.pixels().iter().any(|p| p[3] < 255).then(|| {
        let a = rgba.map(|p| prism_math::Rgb::splat(f32::from(p[3]) / 255.0));
        Arc::new(Texture::new(a).with_uv_convention(UvConvention::Standard))
    });
    let rgb = if alpha.is_some() {
        rgba.map(|p| prism_math::Rgb::from_u8([p[0], p[1], p[2]]) * (f32::from(p[3]) / 255.0))
    } else {
        rgba.to_rgb8().to_rgb_f32()
    };
    doc.textures.push(Arc::new(
        Texture::new(rgb).with_uv_convention(UvConvention::Standard),
    ));
    doc.texture_alpha.push(alpha);
    let index = doc.textures.len() - 1;
    if let Some(d) = bytes {
        cache.push((d.clone(), index));
    }
    Ok(Some(index))
}

fn warn(doc: &mut Document, message: String) {
    let w = Warning { at: None, message };
    if !doc.warnings.contains(&w) {
        doc.warnings.push(w);
    }
}
