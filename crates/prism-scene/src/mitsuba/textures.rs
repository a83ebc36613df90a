//! Mitsuba's textures and image files: `bitmap` and `checkerboard` as prism's material
//! textures, the images an object's `filename` names, and the refusal of nested plugins
//! where prism reads only properties.

use std::sync::Arc;

use super::document::Object;
use super::props::{error, not_supported, unsupported};
use super::to_scene::Builder;
use crate::error::SceneError;
use crate::scene::{MaterialTexture, ScalarTexture};

impl Builder<'_> {
    /// A `bitmap` (PNG, JPEG or OpenEXR; 8-bit colour decoded from sRGB unless `raw`) or
    /// `checkerboard` texture, with its `filter_type`, `wrap_mode` and `to_uv`.
    pub(super) fn texture(&mut self, o: &Object) -> Result<MaterialTexture, SceneError> {
        self.no_nested_plugins(o)?;
        let m = o.transform("to_uv")?;
        let to_uv = [
            m.x_axis.x, m.y_axis.x, m.w_axis.x, m.x_axis.y, m.y_axis.y, m.w_axis.y,
        ]
        .map(|x| x as f32);
        if to_uv.iter().any(|x| !x.is_finite()) {
            return Err(error(
                o,
                format!("{}: to_uv: expected finite numbers", o.label()),
            ));
        }
        match o.kind.as_str() {
            "checkerboard" => {
                // Mitsuba's pattern: color0 where u and v fall in the same half of the unit
                // square, color1 elsewhere; one texel per half, looked up nearest, repeating.
                let (c0, c1) = (o.rgb("color0", [0.4; 3])?, o.rgb("color1", [0.2; 3])?);
                let mut image = prism_image::RgbImage::new(2, 2, c1);
                image.set(0, 0, c0);
                image.set(1, 1, c0);
                Ok(MaterialTexture {
                    to_uv,
                    sampling: prism_image::PixelSampling::Nearest,
                    ..MaterialTexture::new("checkerboard".into(), Arc::new(image))
                })
            }
            "bitmap" => {
                let (file, image) = self.image_file(o, o.boolean("raw", false)?)?;
                let sampling = match o.string("filter_type")?.unwrap_or("bilinear") {
                    "bilinear" => prism_image::PixelSampling::Bilinear,
                    "nearest" => prism_image::PixelSampling::Nearest,
                    other => {
                        return Err(error(
                            o,
                            format!(
                                "{}: filter_type {other:?}: expected \"bilinear\" or \"nearest\"",
                                o.label()
                            ),
                        ))
                    }
                };
                let wrap = match o.string("wrap_mode")?.unwrap_or("repeat") {
                    "repeat" => prism_image::Wrap::Repeat,
                    "mirror" => prism_image::Wrap::Mirror,
                    "clamp" => prism_image::Wrap::Clamp,
                    other => {
                        return Err(error(
                            o,
                            format!(
                            "{}: wrap_mode {other:?}: expected \"repeat\", \"mirror\" or \"clamp\"",
                            o.label()
                        ),
                        ))
                    }
                };
                Ok(MaterialTexture {
                    sampling,
                    wrap,
                    to_uv,
                    ..MaterialTexture::new(file, image)
                })
            }
            _ => Err(unsupported(o)),
        }
    }

    /// The image file an object's `filename` names, with that name: OpenEXR and Radiance
    /// HDR as linear values; PNG or JPEG as `byte / 255`, decoded from sRGB unless `raw`. A file read
    /// before is not read again: its image is shared.
    pub(super) fn image_file(
        &mut self,
        o: &Object,
        raw: bool,
    ) -> Result<(String, Arc<prism_image::RgbImage>), SceneError> {
        let file = o
            .string("filename")?
            .ok_or_else(|| error(o, format!("{}: expected a filename", o.label())))?;
        let path = self.doc.resolve(file);
        self.inputs.push(path.clone());
        if let Some(image) = self.images.get(&(path.clone(), raw)) {
            return Ok((file.to_string(), Arc::clone(image)));
        }
        // The readers' messages name the file already.
        let located = |message: String| error(o, format!("{}: {message}", o.label()));
        let decoding = |e: crate::texture_file::TextureFileError| {
            located(match e {
                crate::texture_file::TextureFileError::NotAnImage => {
                    format!("{file}: {e} (prism reads PNG, JPEG, OpenEXR and Radiance HDR images)")
                }
                e => e.to_string(),
            })
        };
        let bytes = crate::obj::read_bytes(&path).map_err(|e| located(e.to_string()))?;
        let image = if bytes.starts_with(&[0x76, 0x2f, 0x31, 0x01]) {
            prism_image::decode_exr(&bytes, file).map_err(|e| located(e.to_string()))?
        } else if prism_image::is_hdr(&bytes) {
            prism_image::decode_hdr(&bytes, file).map_err(|e| located(e.to_string()))?
        } else if raw {
            crate::texture_file::decode_texture(&bytes, file).map_err(decoding)?
        } else {
            crate::texture_file::decode_color_texture(&bytes, file).map_err(decoding)?
        };
        let image = Arc::new(image);
        self.images.insert((path, raw), Arc::clone(&image));
        Ok((file.to_string(), image))
    }

    /// A texture read for a number (Mitsuba's `eval_1`): the luminance of its texels. A
    /// checkerboard read so puts `color0` where u and v fall in different halves of the
    /// unit square, the opposite of its colours, as Mitsuba's does.
    pub(super) fn scalar_texture(&mut self, o: &Object) -> Result<ScalarTexture, SceneError> {
        let mut t = self.texture(o)?;
        if o.kind == "checkerboard" {
            let mut image = (*t.image).clone();
            let (same, different) = (image.get(0, 0), image.get(1, 0));
            for (x, y) in [(0, 0), (1, 1)] {
                image.set(x, y, different);
            }
            for (x, y) in [(1, 0), (0, 1)] {
                image.set(x, y, same);
            }
            t.image = Arc::new(image);
        }
        Ok(ScalarTexture::Image(t))
    }

    /// Refuses a nested plugin (a texture in place of a colour, say) of an object prism
    /// reads only properties of.
    pub(super) fn no_nested_plugins(&self, o: &Object) -> Result<(), SceneError> {
        match o.children.first() {
            Some(&(_, c)) => {
                let c = &self.doc.objects[c];
                Err(not_supported(
                    c,
                    format!("{} in {}: not supported by prism yet", c.label(), o.label()),
                ))
            }
            None => Ok(()),
        }
    }
}
