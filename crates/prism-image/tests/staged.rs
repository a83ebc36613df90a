//! The image readers on the course's own files (`../shared/assets`).

use prism_image::{read_image, read_png};
use prism_testkit::shared_asset;

/// A baseline JPEG from the ClothSim cube map decodes to an opaque, non-uniform image.
#[test]
fn reads_staged_jpeg() {
    let im = read_image(&shared_asset("clothsim/textures/cube/posx.jpg")).unwrap();
    assert!(im.width() > 0 && im.height() > 0);
    assert!(im.pixels().iter().all(|p| p[3] == 255));
    // Not every pixel is the same colour: the decoder produced an image, not a fill.
    assert!(im.pixels().iter().any(|q| q != &im.pixels()[0]));
}

/// The rasterizer's palette and grey-with-alpha PNGs decode at their recorded sizes.
#[test]
fn reads_staged_palette_and_grey_alpha_pngs() {
    let seal = read_png(&shared_asset("rasterizer/img/seal.png")).unwrap();
    assert_eq!((seal.width(), seal.height()), (260, 260));
    let grid = read_png(&shared_asset("rasterizer/img/grid.png")).unwrap();
    assert_eq!((grid.width(), grid.height()), (397, 385));
}
