//! Fuzz the OpenEXR reader and the part files of split renders: any bytes must give an
//! image, a part or an error naming the file, never a panic; a part's pixels always fit its
//! share, and the RGB reader agrees with the all-channel reader on size.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use prism_image::{decode_exr, decode_exr_header, decode_exr_layers};
use prism_render::parts::{Part, PartHeader};

fuzz_target!(|data: &[u8]| {
    let name = "fuzz.exr";
    let file = Path::new(name);
    match decode_exr_header(data, name) {
        Ok(head) => {
            let header = PartHeader::from_exr(&head, file);
            if let Err(e) = &header {
                assert!(e.to_string().starts_with(name), "{e}");
            }
            match decode_exr_layers(data, name) {
                Ok(layers) => {
                    assert_eq!((layers.width, layers.height), (head.width, head.height));
                    let rgb = decode_exr(data, name).expect("the same decoder");
                    assert_eq!((rgb.width(), rgb.height()), (head.width, head.height));
                    match Part::from_exr(&layers, file) {
                        Ok(part) => {
                            let share = &part.header.share;
                            let most = share.samples.len() as u32;
                            assert!(part.sums.pixels().iter().all(|p| p.n <= most));
                        }
                        Err(e) => assert!(e.to_string().starts_with(name), "{e}"),
                    }
                }
                Err(e) => assert!(e.to_string().starts_with(name), "{e}"),
            }
        }
        Err(e) => {
            assert!(e.to_string().starts_with(name), "{e}");
            assert!(decode_exr(data, name).is_err());
        }
    }
});
