//! Standard SVG features, each checked against an independent truth: a closed form (a
//! blur's mass and spread, an offset by whole pixels, a colour matrix on a known colour, a
//! blend mode's formula), or the same picture drawn another way (a clip against the shape
//! it clips to, a pattern against its tiles drawn one by one, text on a straight path against
//! the same text placed with x and y).

use prism_image::Rgba8Image;
use prism_raster::{parse_svg, render, Dialect, Fonts, RasterOptions, Source};

/// Renders an SVG body in a `w` x `h` document at `samples` per pixel.
fn draw_with(body: &str, w: u32, h: u32, samples: u32, fonts: Fonts) -> Rgba8Image {
    let text = format!(
        "<svg xmlns='http://www.w3.org/2000/svg' xmlns:xlink='http://www.w3.org/1999/xlink' \
         width='{w}' height='{h}'>{body}</svg>"
    );
    let source = Source {
        name: "feature.svg".into(),
        fonts,
        ..Source::default()
    };
    let doc = parse_svg(&text, Dialect::Svg, &source).unwrap_or_else(|e| panic!("{e}"));
    let opts = RasterOptions {
        width: w,
        height: h,
        samples,
        ..RasterOptions::default()
    };
    render(&doc, &opts).expect("render").0
}

fn draw(body: &str, w: u32, h: u32) -> Rgba8Image {
    draw_with(body, w, h, 1, Fonts::default())
}

fn px(img: &Rgba8Image, x: u32, y: u32) -> [i32; 4] {
    img.get(x, y).map(i32::from)
}

fn near(a: [i32; 4], b: [i32; 4], tol: i32) -> bool {
    a.iter().zip(&b).all(|(x, y)| (x - y).abs() <= tol)
}

/// The largest channel difference between two images of the same size.
fn max_diff(a: &Rgba8Image, b: &Rgba8Image) -> i32 {
    assert_eq!(a.width(), b.width());
    a.pixels()
        .iter()
        .zip(b.pixels())
        .flat_map(|(p, q)| (0..4).map(move |c| (i32::from(p[c]) - i32::from(q[c])).abs()))
        .max()
        .unwrap_or(0)
}

/// Same picture another way: a rectangle clipped by a circle equals the circle filled; an
/// even-odd clip rule cuts the hole of a ring; a nested clip path intersects.
#[test]
fn clip_path_equals_the_shape_it_clips_to() {
    let clipped = draw_with(
        "<clipPath id='c'><circle cx='20' cy='20' r='12'/></clipPath>\
         <rect width='40' height='40' fill='blue' clip-path='url(#c)'/>",
        40,
        40,
        16,
        Fonts::default(),
    );
    let plain = draw_with(
        "<circle cx='20' cy='20' r='12' fill='blue'/>",
        40,
        40,
        16,
        Fonts::default(),
    );
    assert!(max_diff(&clipped, &plain) <= 1);
    let ring = draw(
        "<clipPath id='c'><path clip-rule='evenodd' d='M0 0H40V40H0Z M10 10H30V30H10Z'/></clipPath>\
         <rect width='40' height='40' fill='red' clip-path='url(#c)'/>",
        40,
        40,
    );
    assert_eq!(px(&ring, 20, 20)[3], 0);
    assert_eq!(px(&ring, 5, 5), [255, 0, 0, 255]);
    let nested = draw(
        "<clipPath id='a'><rect width='20' height='40'/></clipPath>\
         <clipPath id='b' clip-path='url(#a)'><rect width='40' height='20'/></clipPath>\
         <rect width='40' height='40' fill='red' clip-path='url(#b)'/>",
        40,
        40,
    );
    assert_eq!(px(&nested, 10, 10)[3], 255);
    assert_eq!(px(&nested, 30, 10)[3], 0);
    assert_eq!(px(&nested, 10, 30)[3], 0);
}

/// Closed form: a luminance mask of grey `g` scales alpha by `g` (the luminance of a grey
/// is the grey); an alpha mask by its opacity; a mask's region clips it.
#[test]
fn masks_scale_by_luminance_or_alpha() {
    let lum = draw(
        "<mask id='m'><rect width='40' height='40' fill='rgb(102,102,102)'/></mask>\
         <rect width='40' height='40' fill='black' mask='url(#m)'/>",
        40,
        40,
    );
    assert!(
        near(px(&lum, 20, 20), [0, 0, 0, 102], 1),
        "{:?}",
        px(&lum, 20, 20)
    );
    let alpha = draw(
        "<mask id='m' mask-type='alpha'><rect width='40' height='40' fill='black' \
         fill-opacity='0.5'/></mask><rect width='40' height='40' fill='black' mask='url(#m)'/>",
        40,
        40,
    );
    assert!(near(px(&alpha, 20, 20), [0, 0, 0, 128], 1));
    let region = draw(
        "<mask id='m' maskUnits='userSpaceOnUse' x='0' y='0' width='20' height='40'>\
         <rect width='40' height='40' fill='white'/></mask>\
         <rect width='40' height='40' fill='black' mask='url(#m)'/>",
        40,
        40,
    );
    assert_eq!(px(&region, 10, 20)[3], 255);
    assert_eq!(px(&region, 30, 20)[3], 0);
}

/// Same picture another way: a 2x2 checker pattern equals its squares drawn one by one.
#[test]
fn pattern_equals_its_tiles_drawn_one_by_one() {
    let patterned = draw(
        "<pattern id='p' patternUnits='userSpaceOnUse' width='10' height='10'>\
         <rect width='5' height='5' fill='green'/><rect x='5' y='5' width='5' height='5' \
         fill='green'/></pattern><rect width='40' height='40' fill='url(#p)'/>",
        40,
        40,
    );
    let mut body = String::new();
    for j in 0..8 {
        for i in 0..8 {
            if (i + j) % 2 == 0 {
                body += &format!(
                    "<rect x='{}' y='{}' width='5' height='5' fill='green'/>",
                    i * 5,
                    j * 5
                );
            }
        }
    }
    let tiles = draw(&body, 40, 40);
    assert!(
        max_diff(&patterned, &tiles) <= 1,
        "{}",
        max_diff(&patterned, &tiles)
    );
}

/// Closed forms of every `mix-blend-mode` (W3C formulas, written out here) for one opaque
/// source colour over one opaque backdrop colour.
#[test]
fn every_blend_mode_matches_its_formula() {
    let (b, s) = ([0.2f64, 0.6, 0.9], [0.7f64, 0.3, 0.5]);
    let sep = |f: fn(f64, f64) -> f64| [f(b[0], s[0]), f(b[1], s[1]), f(b[2], s[2])];
    let hard = |b: f64, s: f64| {
        if s <= 0.5 {
            b * 2.0 * s
        } else {
            let t = 2.0 * s - 1.0;
            b + t - b * t
        }
    };
    let lum = |c: [f64; 3]| 0.3 * c[0] + 0.59 * c[1] + 0.11 * c[2];
    let clip = |c: [f64; 3]| {
        let l = lum(c);
        let (n, x) = (c[0].min(c[1]).min(c[2]), c[0].max(c[1]).max(c[2]));
        let mut c = c;
        if n < 0.0 {
            c = c.map(|v| l + (v - l) * l / (l - n));
        }
        if x > 1.0 {
            c = c.map(|v| l + (v - l) * (1.0 - l) / (x - l));
        }
        c
    };
    let set_lum = |c: [f64; 3], l: f64| {
        let d = l - lum(c);
        clip(c.map(|v| v + d))
    };
    let sat = |c: [f64; 3]| c[0].max(c[1]).max(c[2]) - c[0].min(c[1]).min(c[2]);
    let set_sat = |c: [f64; 3], s: f64| {
        let (x, n) = (c[0].max(c[1]).max(c[2]), c[0].min(c[1]).min(c[2]));
        c.map(|v| if x > n { (v - n) * s / (x - n) } else { 0.0 })
    };
    let cases: Vec<(&str, [f64; 3])> = vec![
        ("normal", s),
        ("multiply", sep(|b, s| b * s)),
        ("screen", sep(|b, s| b + s - b * s)),
        (
            "overlay",
            sep(|b, s| {
                if b <= 0.5 {
                    s * 2.0 * b
                } else {
                    let t = 2.0 * b - 1.0;
                    s + t - s * t
                }
            }),
        ),
        ("darken", sep(f64::min)),
        ("lighten", sep(f64::max)),
        (
            "color-dodge",
            sep(|b, s| {
                if s >= 1.0 {
                    1.0
                } else {
                    (b / (1.0 - s)).min(1.0)
                }
            }),
        ),
        (
            "color-burn",
            sep(|b, s| {
                if s <= 0.0 {
                    0.0
                } else {
                    1.0 - ((1.0 - b) / s).min(1.0)
                }
            }),
        ),
        (
            "hard-light",
            [hard(b[0], s[0]), hard(b[1], s[1]), hard(b[2], s[2])],
        ),
        (
            "soft-light",
            sep(|b, s| {
                if s <= 0.5 {
                    b - (1.0 - 2.0 * s) * b * (1.0 - b)
                } else {
                    let d = if b <= 0.25 {
                        ((16.0 * b - 12.0) * b + 4.0) * b
                    } else {
                        b.sqrt()
                    };
                    b + (2.0 * s - 1.0) * (d - b)
                }
            }),
        ),
        ("difference", sep(|b, s| (b - s).abs())),
        ("exclusion", sep(|b, s| b + s - 2.0 * b * s)),
        ("hue", set_lum(set_sat(s, sat(b)), lum(b))),
        ("saturation", set_lum(set_sat(b, sat(s)), lum(b))),
        ("color", set_lum(s, lum(b))),
        ("luminosity", set_lum(b, lum(s))),
        ("plus-lighter", sep(|b, s| (b + s).min(1.0))),
    ];
    let hex = |c: [f64; 3]| {
        format!(
            "rgb({},{},{})",
            (c[0] * 255.0).round(),
            (c[1] * 255.0).round(),
            (c[2] * 255.0).round()
        )
    };
    for (mode, want) in cases {
        let img = draw(
            &format!(
                "<rect width='10' height='10' fill='{}'/>\
                 <rect width='10' height='10' fill='{}' style='mix-blend-mode:{mode}'/>",
                hex(b),
                hex(s)
            ),
            10,
            10,
        );
        let want = [want[0], want[1], want[2]].map(|v| (v * 255.0).round() as i32);
        let got = px(&img, 5, 5);
        assert!(
            near(got, [want[0], want[1], want[2], 255], 2),
            "{mode}: got {got:?}, want {want:?}"
        );
    }
}

fn filtered(filter: &str, shape: &str) -> Rgba8Image {
    draw(
        &format!(
            "<filter id='f' filterUnits='userSpaceOnUse' x='0' y='0' width='40' height='40'>\
             {filter}</filter><g filter='url(#f)'>{shape}</g>"
        ),
        40,
        40,
    )
}

const SQUARE: &str = "<rect x='10' y='10' width='20' height='20' fill='rgb(255,0,0)'/>";

/// Closed form: a Gaussian blur keeps the square's alpha mass (400 pixels) and spreads it
/// with the deviation asked for.
#[test]
fn gaussian_blur_keeps_mass_and_spreads_by_sigma() {
    let img = draw(
        "<filter id='f' filterUnits='userSpaceOnUse' x='-40' y='-40' width='120' height='120'>\
         <feGaussianBlur stdDeviation='3'/></filter>\
         <rect x='10' y='10' width='20' height='20' fill='red' filter='url(#f)'/>",
        40,
        40,
    );
    let mass: f64 = img.pixels().iter().map(|p| f64::from(p[3]) / 255.0).sum();
    assert!((mass - 400.0).abs() < 8.0, "mass {mass}");
    // Along a row through the middle, the edge profile is the Gaussian's integral: at the
    // edge half, one sigma inside about 84%.
    let a = |x: u32| f64::from(px(&img, x, 20)[3]) / 255.0;
    assert!((a(10) - 0.5).abs() < 0.08, "edge {}", a(10));
    assert!((a(13) - 0.84).abs() < 0.08, "one sigma in {}", a(13));
}

/// Closed form: `feOffset` by whole pixels moves every pixel by exactly that much.
#[test]
fn offset_moves_by_whole_pixels() {
    let img = filtered("<feOffset dx='5' dy='-3'/>", SQUARE);
    let plain = draw(SQUARE, 40, 40);
    for y in 0..40 {
        for x in 0..40 {
            let (sx, sy) = (x as i32 - 5, y as i32 + 3);
            let want = if (0..40).contains(&sx) && (0..40).contains(&sy) {
                px(&plain, sx as u32, sy as u32)
            } else {
                [0; 4]
            };
            assert_eq!(px(&img, x, y), want, "({x}, {y})");
        }
    }
}

/// Closed forms: flood fills the region; a colour matrix, a component transfer and an
/// arithmetic composite give known colours (sRGB arithmetic throughout).
#[test]
fn flood_matrix_transfer_and_arithmetic_on_known_colours() {
    let srgb = " color-interpolation-filters='sRGB'";
    let flood = filtered(
        &format!("<feFlood flood-color='rgb(0,128,255)' flood-opacity='0.5'{srgb}/>"),
        "",
    );
    assert!(
        near(px(&flood, 3, 3), [0, 128, 255, 128], 1),
        "{:?}",
        px(&flood, 3, 3)
    );
    // Swap red and green, halve blue's weight into alpha untouched.
    let m = "0 1 0 0 0  1 0 0 0 0  0 0 0.5 0 0  0 0 0 1 0";
    let mat = filtered(
        &format!("<feColorMatrix type='matrix' values='{m}'{srgb}/>"),
        "<rect width='40' height='40' fill='rgb(200,100,50)'/>",
    );
    assert!(
        near(px(&mat, 5, 5), [100, 200, 25, 255], 1),
        "{:?}",
        px(&mat, 5, 5)
    );
    let transfer = filtered(
        &format!(
            "<feComponentTransfer{srgb}><feFuncR type='linear' slope='0.5' intercept='0.25'/>\
             <feFuncG type='table' tableValues='1 0'/><feFuncB type='discrete' \
             tableValues='0 1'/></feComponentTransfer>"
        ),
        "<rect width='40' height='40' fill='rgb(102,51,204)'/>",
    );
    // R: 0.5 * 0.4 + 0.25 = 0.45; G: 1 - 0.2 = 0.8; B: 0.8 is in the upper half: 1.
    assert!(
        near(px(&transfer, 5, 5), [115, 204, 255, 255], 1),
        "{:?}",
        px(&transfer, 5, 5)
    );
    let arith = filtered(
        &format!(
            "<feFlood flood-color='rgb(51,51,51)' result='a'/>\
             <feComposite in='SourceGraphic' in2='a' operator='arithmetic' k1='0' k2='1' \
             k3='1' k4='0'{srgb}/>"
        ),
        "<rect width='40' height='40' fill='rgb(102,0,0)'/>",
    );
    // Premultiplied sums of two opaque colours, clamped to alpha 1.
    assert!(
        near(px(&arith, 5, 5), [153, 51, 51, 255], 1),
        "{:?}",
        px(&arith, 5, 5)
    );
}

/// Same picture another way: `feMerge` of a flood and the source equals the source drawn
/// over a rectangle; `feBlend` multiply matches the formula; `feDropShadow` equals the
/// shadow built from its parts.
#[test]
fn merge_blend_and_drop_shadow_equal_their_parts() {
    let srgb = " color-interpolation-filters='sRGB'";
    let merged = filtered(
        &format!(
            "<feFlood flood-color='blue' result='bg'{srgb}/><feMerge{srgb}><feMergeNode in='bg'/>\
             <feMergeNode in='SourceGraphic'/></feMerge>"
        ),
        SQUARE,
    );
    let drawn = draw(
        &format!("<rect width='40' height='40' fill='blue'/>{SQUARE}"),
        40,
        40,
    );
    assert!(max_diff(&merged, &drawn) <= 1);
    let blended = filtered(
        &format!(
            "<feFlood flood-color='rgb(128,128,128)' result='bg'/>\
             <feBlend in='SourceGraphic' in2='bg' mode='multiply'{srgb}/>"
        ),
        "<rect width='40' height='40' fill='rgb(255,102,0)'/>",
    );
    assert!(
        near(px(&blended, 5, 5), [128, 51, 0, 255], 1),
        "{:?}",
        px(&blended, 5, 5)
    );
    let shadow = filtered(
        &format!("<feDropShadow dx='4' dy='4' stdDeviation='0' flood-color='black'{srgb}/>"),
        SQUARE,
    );
    let parts = draw(
        &format!("<rect x='14' y='14' width='20' height='20' fill='black'/>{SQUARE}"),
        40,
        40,
    );
    assert!(
        max_diff(&shadow, &parts) <= 1,
        "{}",
        max_diff(&shadow, &parts)
    );
}

/// Closed forms: dilation by 3 grows the square by 3 on every side, erosion shrinks it;
/// `feTile` repeats its input's subregion; a constant displacement map of 0.5 moves
/// nothing; an identity convolution kernel changes nothing.
#[test]
fn morphology_tile_displacement_and_convolution() {
    let grown = filtered("<feMorphology operator='dilate' radius='3'/>", SQUARE);
    assert_eq!(px(&grown, 7, 7)[3], 255);
    assert_eq!(px(&grown, 6, 20)[3], 0);
    assert_eq!(px(&grown, 32, 32)[3], 255);
    assert_eq!(px(&grown, 33, 20)[3], 0);
    let shrunk = filtered("<feMorphology operator='erode' radius='3'/>", SQUARE);
    assert_eq!(px(&shrunk, 12, 20)[3], 0);
    assert_eq!(px(&shrunk, 13, 20)[3], 255);
    let tiled = filtered(
        "<feOffset x='10' y='10' width='10' height='10' result='t'/><feTile in='t'/>",
        "<rect x='10' y='10' width='5' height='10' fill='red'/>",
    );
    for (x, y) in [(2, 2), (12, 12), (22, 32), (32, 2)] {
        assert_eq!(px(&tiled, x, y)[3], 255, "({x}, {y})");
        assert_eq!(px(&tiled, x + 5, y)[3], 0, "({}, {y})", x + 5);
    }
    let still = filtered(
        "<feFlood flood-color='rgb(128,128,128)' result='map'/>\
         <feDisplacementMap in='SourceGraphic' in2='map' scale='0' xChannelSelector='R' \
         yChannelSelector='G'/>",
        SQUARE,
    );
    assert!(max_diff(&still, &draw(SQUARE, 40, 40)) <= 1);
    let same = filtered(
        "<feConvolveMatrix order='3' kernelMatrix='0 0 0 0 1 0 0 0 0'/>",
        SQUARE,
    );
    assert!(max_diff(&same, &draw(SQUARE, 40, 40)) <= 1);
}

/// Closed forms of lighting on a flat surface lit from straight above: diffuse gives
/// `kd * colour` everywhere; specular gives `ks * colour` with alpha its largest channel.
#[test]
fn lighting_on_a_flat_surface() {
    let srgb = " color-interpolation-filters='sRGB'";
    let diffuse = filtered(
        &format!(
            "<feDiffuseLighting diffuseConstant='0.5' lighting-color='rgb(255,200,100)'{srgb}>\
             <feDistantLight azimuth='0' elevation='90'/></feDiffuseLighting>"
        ),
        "<rect width='40' height='40' fill='black'/>",
    );
    assert!(
        near(px(&diffuse, 20, 20), [128, 100, 50, 255], 1),
        "{:?}",
        px(&diffuse, 20, 20)
    );
    let specular = filtered(
        &format!(
            "<feSpecularLighting specularConstant='1' specularExponent='4' \
             lighting-color='rgb(0,255,0)'{srgb}><feDistantLight azimuth='0' elevation='90'/>\
             </feSpecularLighting>"
        ),
        "<rect width='40' height='40' fill='black'/>",
    );
    assert!(
        near(px(&specular, 20, 20), [0, 255, 0, 255], 1),
        "{:?}",
        px(&specular, 20, 20)
    );
}

/// Property: `feImage` of an element draws that element where it stands; turbulence fills
/// its region with the same values for the same seed.
#[test]
fn fe_image_and_turbulence() {
    let img = draw(
        &format!(
            "<defs>{}</defs><filter id='f' filterUnits='userSpaceOnUse' x='0' y='0' \
             width='40' height='40'><feImage href='#sq'/></filter>\
             <rect width='1' height='1' filter='url(#f)'/>",
            SQUARE.replace("<rect", "<rect id='sq'")
        ),
        40,
        40,
    );
    assert!(max_diff(&img, &draw(SQUARE, 40, 40)) <= 1);
    // Under a transform, the element is drawn from the primitive subregion's corner.
    let moved = draw(
        &format!(
            "<defs>{}</defs><filter id='f' filterUnits='userSpaceOnUse' x='0' y='0' \
             width='40' height='40'><feImage href='#sq'/></filter>\
             <g transform='translate(5 5)' filter='url(#f)'><rect width='1' height='1'/></g>",
            SQUARE.replace("<rect", "<rect id='sq'")
        ),
        40,
        40,
    );
    let shifted = draw(
        &format!("<g transform='translate(5 5)'>{SQUARE}</g>"),
        40,
        40,
    );
    assert!(max_diff(&moved, &shifted) <= 1);
    let a = filtered(
        "<feTurbulence baseFrequency='0.05' numOctaves='2' seed='3'/>",
        "",
    );
    let b = filtered(
        "<feTurbulence baseFrequency='0.05' numOctaves='2' seed='3'/>",
        "",
    );
    let c = filtered(
        "<feTurbulence baseFrequency='0.05' numOctaves='2' seed='4'/>",
        "",
    );
    assert_eq!(a.pixels(), b.pixels());
    assert_ne!(a.pixels(), c.pixels());
    // Turbulence is |noise| summed: zero only at lattice points, so nearly everywhere inked.
    let inked = a.pixels().iter().filter(|p| p[3] > 0).count();
    assert!(inked > 1500, "{inked} of 1600 pixels");
}

/// The DejaVu fonts Debian installs (`fonts-dejavu-core`), which CI installs.
fn dejavu() -> Fonts {
    Fonts {
        dirs: vec!["/usr/share/fonts/truetype/dejavu".into()],
        skip_system: true,
        ..Fonts::default()
    }
}

/// Same picture another way: text on a straight horizontal path equals the same text
/// placed at the path's start with x and y, as ink.
#[test]
fn text_on_a_straight_path_equals_placed_text() {
    let on_path = draw_with(
        "<path id='p' d='M10 40 H190' fill='none'/><text font-family='DejaVu Sans' \
         font-size='20'><textPath href='#p'>Prism text</textPath></text>",
        200,
        60,
        16,
        dejavu(),
    );
    let placed = draw_with(
        "<text x='10' y='40' font-family='DejaVu Sans' font-size='20'>Prism text</text>",
        200,
        60,
        16,
        dejavu(),
    );
    let inked = placed.pixels().iter().filter(|p| p[3] > 0).count();
    assert!(inked > 500, "the text drew {inked} pixels");
    // usvg places glyphs on a path at sub-pixel offsets of their x/y positions (resvg's
    // own pictures of the two differ as much), so the two are compared as ink: the same
    // amount, and the same in every 4x4 block to within 10%.
    let mass = |img: &Rgba8Image| img.pixels().iter().map(|p| f64::from(p[3])).sum::<f64>();
    let (a, b) = (mass(&on_path), mass(&placed));
    assert!((a - b).abs() <= 0.015 * b, "ink {a} against {b}");
    let block = |img: &Rgba8Image, bx: u32, by: u32| -> f64 {
        let mut sum = 0.0;
        for y in by * 4..by * 4 + 4 {
            for x in bx * 4..bx * 4 + 4 {
                sum += f64::from(img.get(x, y)[3]);
            }
        }
        sum / 16.0
    };
    for by in 0..15 {
        for bx in 0..50 {
            let d = (block(&on_path, bx, by) - block(&placed, bx, by)).abs();
            assert!(d <= 26.0, "block ({bx}, {by}) differs by {d}");
        }
    }
}

/// A font family that does not exist draws nothing and warns, as resvg does.
#[test]
fn missing_font_family_warns_and_draws_nothing() {
    let text = "<svg xmlns='http://www.w3.org/2000/svg' width='200' height='60'><text x='10' \
                y='40' font-family='No Such Family' font-size='20'>Prism</text></svg>";
    let source = Source {
        name: "fonts.svg".into(),
        fonts: dejavu(),
        ..Source::default()
    };
    let doc = parse_svg(text, Dialect::Svg, &source).unwrap();
    assert!(doc.items.is_empty());
    assert!(
        doc.warnings
            .iter()
            .any(|w| w.to_string().contains("No match for '\"No Such Family\"'")),
        "{:?}",
        doc.warnings
    );
}

/// Hostile filters stay bounded: a filter region of 10^9 x 10^9 user units is clipped to the
/// image grown by half its size, a blur deviation of 10^6 costs time linear in that area
/// (running sums) and leaves almost nothing of a small square, and a morphology radius of
/// 10^6 is clamped to the image.
#[test]
fn hostile_filter_regions_and_radii_are_bounded() {
    let huge = "<filter id='f' filterUnits='userSpaceOnUse' x='-1e9' y='-1e9' width='2e9' \
                height='2e9'><feGaussianBlur stdDeviation='1e6'/></filter>\
                <rect x='10' y='10' width='20' height='20' fill='red' filter='url(#f)'/>";
    let img = draw(huge, 64, 64);
    assert!(
        img.pixels().iter().all(|p| p[3] <= 1),
        "a 10^6 blur spreads the square out"
    );
    let dilate = "<filter id='f'><feMorphology operator='dilate' radius='1e6'/></filter>\
                  <rect x='10' y='10' width='20' height='20' fill='red' filter='url(#f)'/>";
    let img = draw(dilate, 64, 64);
    assert_eq!(px(&img, 20, 20), [255, 0, 0, 255]);
}

/// A font directory that does not exist is an error naming it, not a silent fallback.
#[test]
fn missing_font_directory_is_an_error() {
    let text = "<svg xmlns='http://www.w3.org/2000/svg' width='20' height='20'>\
                <text x='1' y='15'>A</text></svg>";
    let source = Source {
        name: "fonts.svg".into(),
        fonts: Fonts {
            dirs: vec!["/nonexistent/fonts".into()],
            ..Fonts::default()
        },
        ..Source::default()
    };
    let err = parse_svg(text, Dialect::Svg, &source).unwrap_err();
    assert!(
        err.to_string()
            .starts_with("/nonexistent/fonts: font directory:"),
        "{err}"
    );
}

/// Regression (found by fuzzing: a circle of radius 8.9e27 took 13 GB): curves outside the
/// image are drawn as their chords, so work follows what is seen. Closed forms: a circle
/// around the whole image covers every pixel; a circle of radius 10^6 whose edge crosses
/// the image at x = 20 covers exactly the pixels left of it (usvg keeps coordinates in
/// `f32`, so larger circles lose that precision, in resvg too).
#[test]
fn huge_shapes_draw_what_is_visible() {
    let around = draw(
        "<circle cx='20' cy='20' r='8888888888888888888888888838' fill='red' stroke='blue' \
         stroke-width='3'/>",
        40,
        40,
    );
    assert!(around.pixels().iter().all(|p| *p == [255, 0, 0, 255]));
    let edge = draw("<circle cx='-999980' cy='20' r='1e6' fill='red'/>", 40, 40);
    for y in [0, 20, 39] {
        assert_eq!(px(&edge, 19, y), [255, 0, 0, 255], "row {y}");
        assert_eq!(px(&edge, 20, y)[3], 0, "row {y}");
    }
}
