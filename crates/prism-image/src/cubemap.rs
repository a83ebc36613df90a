//! [`CubeMap`], six square faces looked up by direction as OpenGL does: the face and its
//! (s, t) from the specification's cube-map table, bilinear inside one face with
//! clamp-to-edge (not seamless), through the one [`Texture`] sampler.

use prism_math::{Rgb, Vec2, Vec3};

use crate::error::ImageError;
use crate::texture::{PixelSampling, Texture, Wrap};
use crate::RgbImage;

/// The faces in OpenGL's order: +X, -X, +Y, -Y, +Z, -Z (files `posx`, `negx`, `posy`,
/// `negy`, `posz`, `negz`).
pub const CUBE_FACES: [&str; 6] = ["posx", "negx", "posy", "negy", "posz", "negz"];

/// A cube map: six square faces of one size; each face's first row is `t = 0`.
#[derive(Clone, Debug)]
pub struct CubeMap {
    faces: Vec<Texture>,
}

/// The face (index into [`CUBE_FACES`]) and the `(s, t)` in `[0, 1]` that direction `d`
/// reads, from the OpenGL specification's table: the major axis is the largest absolute
/// component (x before y before z on ties), and
///
/// | face | sc | tc | ma |
/// |---|---|---|---|
/// | +X | -z | -y | x |
/// | -X | +z | -y | x |
/// | +Y | +x | +z | y |
/// | -Y | +x | -z | y |
/// | +Z | +x | -y | z |
/// | -Z | -x | -y | z |
///
/// with `s = (sc / |ma| + 1) / 2`, `t = (tc / |ma| + 1) / 2`. `None` for the zero or a
/// non-finite direction.
#[must_use]
pub fn cube_face(d: Vec3) -> Option<(usize, Vec2)> {
    let a = d.abs();
    if !d.is_finite() || a.max_element() == 0.0 {
        return None;
    }
    let (face, sc, tc, ma) = if a.x >= a.y && a.x >= a.z {
        if d.x >= 0.0 {
            (0, -d.z, -d.y, a.x)
        } else {
            (1, d.z, -d.y, a.x)
        }
    } else if a.y >= a.z {
        if d.y >= 0.0 {
            (2, d.x, d.z, a.y)
        } else {
            (3, d.x, -d.z, a.y)
        }
    } else if d.z >= 0.0 {
        (4, d.x, -d.y, a.z)
    } else {
        (5, -d.x, -d.y, a.z)
    };
    Some((
        face,
        Vec2::new((sc / ma + 1.0) * 0.5, (tc / ma + 1.0) * 0.5),
    ))
}

/// Bytes a cube-map face takes a pixel once read: linear RGB floats and their mipmaps
/// (a third more), beside the 8-bit copy it was decoded into.
const FACE_BYTES_PER_PIXEL: u64 = 12 + 4 + 8;

/// Checks that face `name` is square, not empty, and `side` pixels a side (the first
/// face's).
fn check_face(name: &str, f: &RgbImage, side: u32) -> Result<(), ImageError> {
    let (w, h) = (f.width(), f.height());
    if w == side && h == side && side > 0 {
        return Ok(());
    }
    let first = CUBE_FACES[0];
    let message = if w != h || side == 0 || name == first {
        format!("cube-map faces must be square and of one size: {name} is {w} x {h}")
    } else {
        format!(
            "cube-map faces must be square and of one size: {name} is {w} x {h}, {first} is \
             {side} x {side}"
        )
    };
    Err(ImageError::Decode {
        what: name.to_string(),
        message,
    })
}

impl CubeMap {
    /// Reads the six faces `posx`, `negx`, ... from `dir` (each `.png`, `.jpg` or `.jpeg`,
    /// sRGB bytes read as values in `[0, 1]`, as the course's app uploads them). The first
    /// face's size is checked for all six against the memory budget before the other five
    /// are read, and each face must match it.
    ///
    /// # Errors
    /// [`ImageError::Decode`] naming a missing face or one of another size, or six faces
    /// over the memory budget; a face's own read or decode error.
    pub fn read(dir: &std::path::Path) -> Result<CubeMap, ImageError> {
        let mut faces = Vec::with_capacity(6);
        for name in CUBE_FACES {
            let path = ["png", "jpg", "jpeg"]
                .iter()
                .map(|e| dir.join(format!("{name}.{e}")))
                .find(|p| p.is_file())
                .ok_or_else(|| ImageError::Decode {
                    what: dir.display().to_string(),
                    message: format!("no {name}.png or {name}.jpg"),
                })?;
            let decoded = crate::read_image(&path)?;
            if faces.is_empty() {
                let (w, h) = (u64::from(decoded.width()), u64::from(decoded.height()));
                let bytes = 6 * w * h * FACE_BYTES_PER_PIXEL;
                prism_math::limits::check_memory(bytes).map_err(|over| ImageError::Decode {
                    what: dir.display().to_string(),
                    message: format!("the cube map of six {w}x{h} faces {over}"),
                })?;
            }
            let face = decoded.to_rgb8().to_rgb_f32();
            // A face of another size stops the read here, not after all six.
            let side = faces.first().map_or(face.width(), RgbImage::width);
            check_face(name, &face, side)?;
            faces.push(face);
        }
        let faces: [RgbImage; 6] = faces.try_into().expect("six faces were read");
        CubeMap::new(faces)
    }

    /// A cube map of six faces in [`CUBE_FACES`] order.
    ///
    /// # Errors
    /// [`ImageError::Decode`] naming the face if the faces are not square and of one size.
    pub fn new(faces: [RgbImage; 6]) -> Result<CubeMap, ImageError> {
        let side = faces[0].width();
        for (f, name) in faces.iter().zip(CUBE_FACES) {
            check_face(name, f, side)?;
        }
        Ok(CubeMap {
            faces: faces
                .into_iter()
                .map(|f| Texture::new(f).with_wrap(Wrap::Clamp, Wrap::Clamp))
                .collect(),
        })
    }

    /// The colour seen along `d`: bilinear inside the face [`cube_face`] picks, clamped to
    /// its edges; black for the zero direction.
    #[must_use]
    pub fn sample(&self, d: Vec3) -> Rgb {
        match cube_face(d) {
            Some((face, st)) => self.faces[face].sample_level(st, 0, PixelSampling::Bilinear),
            None => Rgb::BLACK,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The specification's table: each axis direction reads its own face at the centre, and
    /// the corner directions give the (s, t) the table says.
    #[test]
    fn face_selection_table() {
        let c = Vec2::splat(0.5);
        for (d, face) in [
            (Vec3::X, 0),
            (Vec3::NEG_X, 1),
            (Vec3::Y, 2),
            (Vec3::NEG_Y, 3),
            (Vec3::Z, 4),
            (Vec3::NEG_Z, 5),
        ] {
            assert_eq!(cube_face(d), Some((face, c)));
        }
        // +X: sc = -z, tc = -y.
        assert_eq!(
            cube_face(Vec3::new(1.0, 0.5, 0.5)),
            Some((0, Vec2::new(0.25, 0.25)))
        );
        // -X: sc = +z.
        assert_eq!(
            cube_face(Vec3::new(-1.0, 0.5, 0.5)),
            Some((1, Vec2::new(0.75, 0.25)))
        );
        // +Y: sc = +x, tc = +z.
        assert_eq!(
            cube_face(Vec3::new(0.5, 1.0, 0.5)),
            Some((2, Vec2::new(0.75, 0.75)))
        );
        // -Y: tc = -z.
        assert_eq!(
            cube_face(Vec3::new(0.5, -1.0, 0.5)),
            Some((3, Vec2::new(0.75, 0.25)))
        );
        // +Z: sc = +x, tc = -y.
        assert_eq!(
            cube_face(Vec3::new(0.5, 0.5, 1.0)),
            Some((4, Vec2::new(0.75, 0.25)))
        );
        // -Z: sc = -x.
        assert_eq!(
            cube_face(Vec3::new(0.5, 0.5, -1.0)),
            Some((5, Vec2::new(0.25, 0.25)))
        );
        // Ties go to x, then y.
        assert_eq!(cube_face(Vec3::new(1.0, 1.0, 1.0)).unwrap().0, 0);
        assert_eq!(cube_face(Vec3::new(0.0, -1.0, 1.0)).unwrap().0, 3);
        assert_eq!(cube_face(Vec3::ZERO), None);
    }

    /// Each face's colour comes back along its axis; the first file row is t = 0 (towards
    /// -y on the side faces).
    #[test]
    fn faces_and_rows() {
        let faces: [RgbImage; 6] = std::array::from_fn(|i| {
            crate::Image::from_fn(2, 2, |_, y| Rgb::new(i as f32 / 8.0, y as f32, 0.0))
        });
        let cube = CubeMap::new(faces).unwrap();
        let up = cube.sample(Vec3::new(1.0, 0.999, 0.0));
        let down = cube.sample(Vec3::new(1.0, -0.999, 0.0));
        assert_eq!(up.r, 0.0);
        assert!(up.g < 0.01 && down.g > 0.99, "{up:?} {down:?}");
        assert_eq!(cube.sample(Vec3::NEG_Z).r, 5.0 / 8.0);
        let bad = std::array::from_fn(|i| crate::Image::new(2 + (i == 3) as u32, 2, Rgb::BLACK));
        assert!(CubeMap::new(bad).is_err());
    }
}
