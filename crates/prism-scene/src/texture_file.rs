//! Material texture images read from files: PNG or JPEG, decoded to RGB values in [0, 1].

use prism_image::{ImageError, RgbImage};

/// Why a texture file's bytes are not an image; the readers put it under the file, line and
/// element that named the texture.
#[derive(Debug, thiserror::Error)]
pub(crate) enum TextureFileError {
    /// Neither a PNG nor a JPEG signature.
    #[error("expected a PNG or JPEG image")]
    NotAnImage,
    /// The decoder refused it.
    #[error(transparent)]
    Decode(#[from] ImageError),
}

/// The image in `bytes` (PNG or JPEG, told apart by their signatures) as RGB `byte / 255`,
/// grey copied to RGB and alpha dropped. `name` names it in errors.
pub(crate) fn decode_texture(bytes: &[u8], name: &str) -> Result<RgbImage, TextureFileError> {
    let img = if bytes.starts_with(b"\x89PNG\r\n\x1a\n") {
        prism_image::decode_png(bytes, name)?
    } else if bytes.starts_with(&[0xff, 0xd8]) {
        prism_image::decode_jpeg(bytes, name)?
    } else {
        return Err(TextureFileError::NotAnImage);
    };
    Ok(img.to_rgb8().to_rgb_f32())
}

/// [`decode_texture`] with the sRGB encoding of colour images undone: linear albedos.
pub(crate) fn decode_color_texture(bytes: &[u8], name: &str) -> Result<RgbImage, TextureFileError> {
    let img = decode_texture(bytes, name)?;
    Ok(img.map(|c| {
        prism_math::Rgb::new(
            prism_image::srgb_to_linear(c.r),
            prism_image::srgb_to_linear(c.g),
            prism_image::srgb_to_linear(c.b),
        )
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Property: bytes with no image signature and a PNG cut short are told apart, each
    /// with its own message; a PNG round-trips to `byte / 255`, and the colour decoder
    /// undoes sRGB (closed form: 188/255 is about 0.5 linear).
    #[test]
    fn texture_bytes_decode_or_say_why_not() {
        let e = decode_texture(b"GIF89a....", "t.gif").unwrap_err();
        assert!(matches!(e, TextureFileError::NotAnImage));
        assert_eq!(e.to_string(), "expected a PNG or JPEG image");
        let mut img = prism_image::Rgb8Image::new(2, 1, [0, 0, 0]);
        img.set(1, 0, [188, 255, 0]);
        let png = prism_image::encode_png(&img).unwrap();
        let e = decode_texture(&png[..20], "cut.png").unwrap_err();
        assert!(matches!(e, TextureFileError::Decode(_)), "{e}");
        let raw = decode_texture(&png, "t.png").unwrap();
        assert_eq!(raw.get(1, 0).g, 1.0);
        assert_eq!(raw.get(1, 0).r, 188.0 / 255.0);
        let linear = decode_color_texture(&png, "t.png").unwrap();
        assert!(
            (linear.get(1, 0).r - 0.5).abs() < 0.01,
            "{:?}",
            linear.get(1, 0)
        );
    }
}
