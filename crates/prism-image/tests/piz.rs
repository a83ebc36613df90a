//! OpenEXR files with PIZ compression, written by the OpenEXR library and by Mitsuba 3 (the
//! oracles): each decodes to exactly the samples of its uncompressed twin, written by the
//! OpenEXR library from the same data (`tests/piz/NAME.piz.exr` and `NAME.none.exr`).

use std::path::PathBuf;

use prism_image::{read_exr_layers, ExrSamples};

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/piz")
        .join(name)
}

/// The channels of `NAME.piz.exr` equal those of `NAME.none.exr`, bit for bit.
fn same_as_uncompressed(name: &str) {
    let piz = read_exr_layers(&fixture(&format!("{name}.piz.exr"))).expect("the PIZ file reads");
    let none = read_exr_layers(&fixture(&format!("{name}.none.exr"))).expect("the twin reads");
    assert_eq!((piz.width, piz.height), (none.width, none.height), "{name}");
    assert_eq!(piz.channels.len(), none.channels.len(), "{name}");
    for ((a, sa), (b, sb)) in piz.channels.iter().zip(&none.channels) {
        assert_eq!(a, b, "{name}");
        let same = match (sa, sb) {
            (ExrSamples::Float(x), ExrSamples::Float(y)) => x
                .iter()
                .map(|v| v.to_bits())
                .eq(y.iter().map(|v| v.to_bits())),
            (ExrSamples::Uint(x), ExrSamples::Uint(y)) => x == y,
            _ => false,
        };
        assert!(same, "{name}: channel {a} differs");
    }
}

/// Half floats of a smooth gradient with a bright spot: few distinct words, so the
/// 14-bit wavelet; 70 lines, three blocks, the last of 6 lines (an odd line at a level).
#[test]
fn piz_half_gradient() {
    same_as_uncompressed("half_gradient");
}

/// Half floats of smooth data with a little noise, 151 samples wide (an odd column at
/// every level).
#[test]
fn piz_half_noise() {
    same_as_uncompressed("half_noise");
}

/// 32-bit floats mostly constant (the Huffman code's repeats), three blocks.
#[test]
fn piz_float_runs() {
    same_as_uncompressed("float_runs");
}

/// Half, float and uint channels side by side in one line (stored as is: PIZ would not
/// make it smaller).
#[test]
fn piz_mixed_channel_types() {
    same_as_uncompressed("mixed");
}

/// A single pixel (stored as is).
#[test]
fn piz_one_pixel() {
    same_as_uncompressed("one_pixel");
}

/// A file Mitsuba 3 wrote (`mi.Bitmap.write`, PIZ by default): 32-bit floats.
#[test]
fn piz_written_by_mitsuba() {
    same_as_uncompressed("mitsuba");
}

/// One channel of 32-bit floats with random low halves, 800 samples wide: over 16,384
/// distinct words in the block, so the 16-bit (modular) wavelet.
#[test]
fn piz_float_wide_sixteen_bit_wavelet() {
    same_as_uncompressed("float_wide");
}
