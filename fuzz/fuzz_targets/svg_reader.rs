//! Fuzz the SVG readers (both dialects: usvg and the course's) and, for small documents,
//! the rasterizer with its clip paths, masks, patterns and filters: any input must give a
//! document or a located error, never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;
use prism_raster::{parse_svg, render, Dialect, RasterOptions, Source};

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let source = Source {
        name: "fuzz.svg".into(),
        base_dir: "/nonexistent".into(),
        ..Source::default()
    };
    for dialect in [Dialect::Svg, Dialect::Cs184] {
        match parse_svg(text, dialect, &source) {
            Ok(doc) => {
                if doc.items.len() <= 64 {
                    let opts = RasterOptions {
                        width: 32,
                        height: 32,
                        samples: 4,
                        compat: dialect == Dialect::Cs184,
                        ..RasterOptions::default()
                    };
                    let _ = render(&doc, &opts);
                }
            }
            Err(e) => {
                assert!(e.to_string().starts_with("fuzz.svg:"));
            }
        }
    }
});
