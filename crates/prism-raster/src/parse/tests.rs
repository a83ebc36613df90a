//! Hostile documents: deep nesting, `use` fan-out and reference cycles, long `href` and
//! mask chains. Each must end in a located error or a correct document (usvg skipping what
//! it skips), on a test thread's small stack.

use std::path::PathBuf;

use super::*;
use crate::document::Item;

fn parse(text: &str, dialect: Dialect) -> Result<Document, SvgError> {
    let source = Source {
        name: "hostile.svg".into(),
        base_dir: PathBuf::new(),
        ..Source::default()
    };
    parse_svg(text, dialect, &source)
}

fn svg(body: &str) -> String {
    format!(
        "<svg xmlns='http://www.w3.org/2000/svg' xmlns:xlink='http://www.w3.org/1999/xlink' \
         width='10' height='10'>\n{body}</svg>"
    )
}

fn nested(open: &str, close: &str, levels: usize) -> String {
    svg(&format!(
        "{}<rect width='5' height='5'/>{}",
        open.repeat(levels),
        close.repeat(levels)
    ))
}

/// Property: 100,000 levels of `<g>` end in the nesting-limit error, located at the first
/// element past the limit, in both dialects (no recursion per level before the check).
#[test]
fn hundred_thousand_nested_groups_are_a_located_error() {
    let text = nested("<g>", "</g>", 100_000);
    for dialect in [Dialect::Svg, Dialect::Cs184] {
        match parse(&text, dialect) {
            Err(SvgError::NestingLimit { at, element, limit }) => {
                assert_eq!((at.line, element.as_str(), limit), (2, "g", MAX_DEPTH));
            }
            other => panic!("{dialect:?}: expected the nesting limit, got {other:?}"),
        }
    }
}

/// Property: nested `<svg>` viewports count towards the same limit.
#[test]
fn hundred_thousand_nested_viewports_are_a_located_error() {
    let text = nested("<svg width='10' height='10'>", "</svg>", 100_000);
    let err = parse(&text, Dialect::Svg).unwrap_err();
    assert!(matches!(err, SvgError::NestingLimit { .. }), "{err}");
}

/// Closed form: at the limit (the root, 254 groups and the rectangle make 256 levels) the
/// document reads, with its one rectangle; one group more is refused.
#[test]
fn nesting_at_the_limit_reads() {
    for dialect in [Dialect::Svg, Dialect::Cs184] {
        let doc = parse(&nested("<g>", "</g>", MAX_DEPTH - 2), dialect).unwrap();
        assert_eq!(doc.items.len(), 1);
        let err = parse(&nested("<g>", "</g>", MAX_DEPTH - 1), dialect).unwrap_err();
        assert!(matches!(err, SvgError::NestingLimit { .. }), "{err}");
    }
}

/// `k` groups, each `use`-ing the previous one twice, then one `use` of the last.
fn fan_out(k: usize) -> String {
    let mut body = String::from("<defs><g id='g0'><rect width='1' height='1'/></g>\n");
    for i in 1..k {
        body += &format!(
            "<g id='g{i}'><use xlink:href='#g{}'/><use href='#g{}'/></g>\n",
            i - 1,
            i - 1
        );
    }
    body += &format!("</defs><use xlink:href='#g{}'/>\n", k - 1);
    svg(&body)
}

/// Brute-force count: `k` doubling levels draw exactly 2^(k-1) rectangles.
#[test]
fn use_fan_out_under_the_limit_draws_every_copy() {
    let doc = parse(&fan_out(11), Dialect::Svg).unwrap();
    assert_eq!(doc.items.len(), 1 << 10);
}

/// The 2^29-rectangle document is refused by counting, before usvg expands anything.
/// Closed form: group `g_i` expands to `5·2^i − 3` elements (itself, two `use`s, two
/// copies of `g_{i−1}`), first over a million at `g18` (line 20).
#[test]
fn use_fan_out_past_the_limit_is_refused() {
    let err = parse(&fan_out(30), Dialect::Svg).unwrap_err();
    match &err {
        SvgError::UseLimit { at, element, limit } => assert_eq!(
            (at.line, element.as_str(), *limit),
            (20, "g", MAX_USE_ELEMENTS)
        ),
        other => panic!("expected the use limit, got {other:?}"),
    }
    assert!(err.to_string().starts_with("hostile.svg:"), "{err}");
}

/// A `use` of its own ancestor is skipped, as resvg skips it, and what lies outside the
/// cycle is still drawn; a cycle through two groups expands until usvg's element limit and
/// is refused naming the file, as resvg refuses it.
#[test]
fn use_cycles_are_skipped_or_refused() {
    let rect = "<rect width='5' height='5'/>";
    let direct = svg(&format!("<g id='a'><use href='#a'/>{rect}</g>"));
    assert_eq!(parse(&direct, Dialect::Svg).unwrap().items.len(), 1);
    let mutual = svg(&format!(
        "<g id='a'><use href='#b'/></g><g id='b'><use href='#a'/></g>{rect}"
    ));
    let err = parse(&mutual, Dialect::Svg).unwrap_err();
    assert!(matches!(err, SvgError::Usvg { .. }), "{err}");
}

/// 100,000 masks, each masking the content of the next, are refused at the reference that
/// passes the nesting limit (references count as nesting), before usvg recurses.
#[test]
fn mask_chains_are_bounded() {
    let n = 100_000;
    let mut body = String::from("<defs>\n");
    for i in 1..n {
        body += &format!(
            "<mask id='m{i}'><rect width='5' height='5' fill='white' mask='url(#m{})'/></mask>",
            i - 1
        );
    }
    body += &format!(
        "</defs>\n<rect width='5' height='5' mask='url(#m{})'/>",
        n - 1
    );
    let err = parse(&svg(&body), Dialect::Svg).unwrap_err();
    assert!(matches!(err, SvgError::NestingLimit { .. }), "{err}");
    assert_eq!(err.at().line, 3);
}

/// A chain of 100,000 gradients, each `href`-ing the next, is refused at its start; a chain
/// within the limit inherits the stops from its far end.
#[test]
fn gradient_href_chains_are_bounded() {
    let chain = |n: usize| {
        let mut body = String::from(
            "<defs><linearGradient id='l0'><stop offset='0' stop-color='red'/>\
             <stop offset='1' stop-color='blue'/></linearGradient>\n",
        );
        for i in 1..n {
            body += &format!("<linearGradient id='l{i}' href='#l{}'/>", i - 1);
        }
        body += &format!(
            "</defs>\n<rect width='10' height='10' fill='url(#l{})'/>",
            n - 1
        );
        svg(&body)
    };
    let err = parse(&chain(100_000), Dialect::Svg).unwrap_err();
    assert!(matches!(err, SvgError::NestingLimit { .. }), "{err}");
    let doc = parse(&chain(16), Dialect::Svg).unwrap();
    match &doc.items[..] {
        [Item::Fill {
            paint: crate::document::Paint::Gradient(g),
            ..
        }] => assert_eq!(g.stops.len(), 2),
        other => panic!("expected one gradient fill, got {other:?}"),
    }
}

/// Attributes of other namespaces do not stand in for SVG's own (`sodipodi:cx` is not `cx`).
#[test]
fn namespaced_attributes_are_not_svg_attributes() {
    let text = "<svg xmlns='http://www.w3.org/2000/svg' \
                xmlns:sodipodi='http://sodipodi.sourceforge.net/DTD/sodipodi-0.dtd' \
                width='10' height='10'><circle sodipodi:r='0' r='3' cx='5' cy='5'/></svg>";
    let doc = parse(text, Dialect::Svg).unwrap();
    assert_eq!(doc.items.len(), 1);
}

/// Regression (found by fuzzing): text on a path reaching 4.7e24 user units made usvg's
/// arc-length measurement run for minutes; such a path is a located error.
#[test]
fn text_on_a_far_path_is_refused() {
    let far = svg(
        "<path id='p' d='M262 215 A103 103 0 0 1 4687777777777777777777777 215'/>\n\
                   <text><textPath href='#p'>far</textPath></text>",
    );
    let err = parse(&far, Dialect::Svg).unwrap_err();
    assert!(
        err.to_string()
            .contains("hostile.svg:3: textPath: the path the text follows"),
        "{err}"
    );
    let near =
        svg("<path id='p' d='M0 5 H1000000'/><text><textPath href='#p'>near</textPath></text>");
    parse(&near, Dialect::Svg).unwrap();
}

/// Regression (found by fuzzing): a gradient whose `href` chain enters a cycle it did not
/// start (a -> b -> c -> b) made usvg loop for ever; the cycle is a located error. A
/// gradient referring to itself is left to usvg, which stops there.
#[test]
fn gradient_href_cycles_are_refused() {
    let stops = "<stop offset='0' stop-color='red'/>";
    let cyclic = svg(&format!(
        "<linearGradient id='a' href='#b'/>\n<linearGradient id='b' href='#c'/>\n\
         <linearGradient id='c' href='#b'>{stops}</linearGradient>\n\
         <rect width='5' height='5' fill='url(#a)'/>"
    ));
    let err = parse(&cyclic, Dialect::Svg).unwrap_err();
    assert!(
        err.to_string().contains("href leads back to this element"),
        "{err}"
    );
    assert_eq!(err.at().line, 3);
    let own = svg(&format!(
        "<linearGradient id='a' href='#a'>{stops}</linearGradient>\
         <rect width='5' height='5' fill='url(#a)'/>"
    ));
    parse(&own, Dialect::Svg).unwrap();
}
