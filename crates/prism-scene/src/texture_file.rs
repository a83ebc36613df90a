//! Material texture images read from files: PNG or JPEG, decoded to RGB values in [0, 1].

use prism_image::RgbImage;

/// The image in `bytes` (PNG or JPEG, told apart by their signatures) as RGB `byte / 255`,
/// grey copied to RGB and alpha dropped. `name` names it in errors.
pub(crate) fn decode_texture(bytes: &[u8], name: &str) -> Result<RgbImage, String> {
    let img = if bytes.starts_with(b"\x89PNG\r\n\x1a\n") {
        prism_image::decode_png(bytes, name)
    } else if bytes.starts_with(&[0xff, 0xd8]) {
        prism_image::decode_jpeg(bytes, name)
    } else {
        return Err("expected a PNG or JPEG image".into());
    };
    Ok(img.map_err(|e| e.to_string())?.to_rgb8().to_rgb_f32())
}

/// [`decode_texture`] with the sRGB encoding of colour images undone: linear albedos.
pub(crate) fn decode_color_texture(bytes: &[u8], name: &str) -> Result<RgbImage, String> {
    let img = decode_texture(bytes, name)?;
    Ok(img.map(|c| {
        prism_math::Rgb::new(
            prism_image::srgb_to_linear(c.r),
            prism_image::srgb_to_linear(c.g),
            prism_image::srgb_to_linear(c.b),
        )
    }))
}
