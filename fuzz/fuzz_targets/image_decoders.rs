//! Fuzz the image decoders (PNG, JPEG, OpenEXR, Radiance HDR) under a small memory budget: any bytes give
//! an image or an error naming the source, never a panic, and a decoded image never holds
//! more than one image's budget allows.
#![no_main]

use libfuzzer_sys::fuzz_target;
use prism_image::{decode_exr, decode_exr_layers, decode_hdr, decode_jpeg, decode_png, ImageError};
use prism_math::limits;

/// 64 MiB in all, 16 MiB an image: far below libFuzzer's own memory limit, so a decoder
/// that allocated what a header claims, past the budget, would be caught.
const BUDGET: u64 = 64 << 20;

fn check<T>(name: &str, r: Result<T, ImageError>, pixels: impl Fn(&T) -> (u64, u64)) {
    match r {
        Ok(image) => {
            let (n, bytes_per_pixel) = pixels(&image);
            assert!(n * bytes_per_pixel <= limits::image_budget(), "{n} pixels");
        }
        Err(e) => assert!(e.to_string().starts_with(name), "{e}"),
    }
}

fuzz_target!(|data: &[u8]| {
    limits::set_memory_budget(BUDGET);
    let size = |w: u32, h: u32| u64::from(w) * u64::from(h);
    check("f.png", decode_png(data, "f.png"), |i| (size(i.width(), i.height()), 8));
    check("f.jpg", decode_jpeg(data, "f.jpg"), |i| (size(i.width(), i.height()), 8));
    check("f.exr", decode_exr_layers(data, "f.exr"), |l| {
        (size(l.width, l.height), 4 * l.channels.len() as u64)
    });
    check("f.exr", decode_exr(data, "f.exr"), |i| (size(i.width(), i.height()), 0));
    check("f.hdr", decode_hdr(data, "f.hdr"), |i| (size(i.width(), i.height()), 12));
});
