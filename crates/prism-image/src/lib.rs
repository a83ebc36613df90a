//! Floor-1 imaging for prism: the one image type, sRGB/linear conversions, PNG/JPEG/EXR IO
//! (PNG and EXR also written row by row, and tiled OpenEXR read and written a tile at a
//! time) and Radiance HDR input, the one texture sampler (mipmaps, nearest/bilinear/trilinear),
//! image-difference metrics, cube maps looked up as OpenGL does, heat maps, bloom, BMP
//! output, animated PNGs and montages (pictures side by side in a grid).
#![warn(missing_docs)]

mod animation;
mod bloom;
mod cubemap;
mod diff;
mod error;
mod exr;
mod exr_tiled;
mod exr_write;
mod hdr;
mod heatmap;
mod image;
mod io;
mod montage;
mod piz;
mod png_rows;
mod srgb;
mod texture;

pub use animation::{ApngEncoder, GifEncoder};
pub use bloom::{bloom_weights, Bloom};
pub use cubemap::{cube_face, CubeMap, CUBE_FACES};
pub use diff::{compare_rgb8, DiffStats};
pub use error::ImageError;
pub use exr::{
    decode_exr, decode_exr_header, decode_exr_layers, read_exr, read_exr_layers, read_radiance,
    ExrLayers, ExrSamples,
};
pub use exr_tiled::{TiledExrReader, TiledExrWriter};
pub use exr_write::{encode_exr, encode_exr_layers, write_exr, write_exr_layers, ExrRowWriter};
pub use hdr::{decode_hdr, is_hdr};
pub use heatmap::{heat_colour, heatmap};
pub use image::{over_background8, srgb8, truncated8, Image, Rgb8Image, RgbImage, Rgba8Image};
pub use io::{
    decode_gif, decode_jpeg, decode_png, decode_webp, encode_bmp, encode_jpeg, encode_png,
    encode_png_rgba, read_image, read_png, remove_temporaries_before_exit, write_atomic,
    write_atomic_with, write_bmp, write_jpeg, write_png, write_png_rgba, AtomicFile, JPEG_QUALITY,
    MAX_IMAGE_FILE_BYTES,
};
pub use montage::montage;
pub use png_rows::{PngColor, PngRowWriter};
pub use srgb::{linear_to_srgb, linear_to_srgb8, srgb8_to_linear, srgb_to_linear};
pub use texture::{LevelSampling, PixelSampling, Texture, UvConvention, Wrap};
