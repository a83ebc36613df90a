//! The CS184 HW1 dialect (`--compat cs184`), read as the course renderer reads it: only
//! `width`/`height` of the root, no style inheritance, hex colours with anything else black,
//! numbers rounded to `f32`, `scale(s)` meaning `scale(s, 1)`, filled shapes triangulated by
//! ear clipping, outlines as one-pixel DDA lines, and unknown elements skipped.

use std::collections::HashMap;

use prism_math::{DVec2, Rgb};
use roxmltree::Node;

use super::common::{
    number_list, number_with_unit, parse_transform, ElementAt, PlainAttribute, SvgError, MAX_DEPTH,
    MAX_ITEMS,
};
use super::context::{element_loc, Ctx};
use super::course::course_element;
use super::images::image_item;
use super::number::Precision;
use crate::document::{Document, Item, Mat3};
use crate::triangulate::ear_clip;

const P: Precision = Precision::F32;

/// The course's `Color::fromHex`: an optional `#`, then the longest hex prefix as one
/// integer; no digits (e.g. `none`) is black.
pub(crate) fn hex_color(s: &str) -> Rgb {
    let t = s.trim();
    let t = t.strip_prefix('#').unwrap_or(t);
    let digits: String = t.chars().take_while(char::is_ascii_hexdigit).collect();
    let v = u32::from_str_radix(&digits, 16).unwrap_or(0);
    let ch = |shift: u32| (f64::from((v >> shift) & 0xff) / 255.0) as f32;
    Rgb::new(ch(16), ch(8), ch(0))
}

fn num_attr(node: &Node, name: &str, loc: &ElementAt) -> Result<f64, SvgError> {
    match node.attr(name) {
        None => Ok(0.0),
        Some(s) => Ok(number_with_unit(s, P, loc, name)?.0),
    }
}

fn points_attr(node: &Node, name: &str, loc: &ElementAt) -> Result<Vec<DVec2>, SvgError> {
    let l = number_list(node.attr(name).unwrap_or(""), P, loc, name)?;
    if l.len() % 2 != 0 {
        return Err(loc.err(format!(
            "{name}: expected x,y pairs, found {} numbers",
            l.len()
        )));
    }
    Ok(l.chunks_exact(2).map(|c| DVec2::new(c[0], c[1])).collect())
}

pub(crate) fn parse<'a>(root: Node<'a, 'a>, ctx: &mut Ctx<'a>) -> Result<Document, SvgError> {
    let loc = element_loc(ctx, &root);
    let size = |name: &str| -> Result<f64, SvgError> {
        let s = root
            .attr(name)
            .ok_or_else(|| loc.err(format!("expected a {name} attribute on the root svg")))?;
        let v = number_with_unit(s, P, &loc, name)?.0;
        if v > 0.0 {
            Ok(v)
        } else {
            Err(loc.err(format!("{name}: expected a positive size, found {s:?}")))
        }
    };
    let mut doc = Document {
        width: size("width")?,
        height: size("height")?,
        ..Document::default()
    };
    let mut textures = HashMap::new();
    walk(root, Mat3::IDENTITY, 1, ctx, &mut doc, &mut textures)?;
    Ok(doc)
}

fn walk<'a>(
    parent: Node<'a, 'a>,
    ctm: Mat3,
    depth: usize,
    ctx: &mut Ctx<'a>,
    doc: &mut Document,
    textures: &mut HashMap<String, usize>,
) -> Result<(), SvgError> {
    for node in parent.children().filter(Node::is_element) {
        let loc = element_loc(ctx, &node);
        if depth >= MAX_DEPTH {
            return Err(loc.nesting_limit());
        }
        if doc.items.len() > MAX_ITEMS {
            return Err(loc.items_limit());
        }
        let name = node.tag_name().name();
        let t = match node.attr("transform") {
            Some(s) => ctm.mul(&parse_transform(s, P, &loc, true)?),
            None => ctm,
        };
        let fill = node.attr("fill").map_or(Rgb::BLACK, hex_color);
        let stroke = node.attr("stroke").map(hex_color);
        let stroke_opacity = match node.attr("stroke-opacity") {
            Some(s) => number_with_unit(s, P, &loc, "stroke-opacity")?
                .0
                .clamp(0.0, 1.0) as f32,
            None => 1.0,
        };
        match name {
            "g" => walk(node, t, depth + 1, ctx, doc, textures)?,
            "rect" => {
                let (x, y) = (
                    num_attr(&node, "x", &loc)? as f32,
                    num_attr(&node, "y", &loc)? as f32,
                );
                let (w, h) = (
                    num_attr(&node, "width", &loc)? as f32,
                    num_attr(&node, "height", &loc)? as f32,
                );
                if w == 0.0 && h == 0.0 {
                    doc.items.push(Item::Point {
                        at: DVec2::new(f64::from(x), f64::from(y)),
                        transform: t,
                        color: fill,
                    });
                    continue;
                }
                let p = |a: f32, b: f32| DVec2::new(f64::from(a), f64::from(b));
                let (p0, p1, p2, p3) = (p(x, y), p(x + w, y), p(x, y + h), p(x + w, y + h));
                doc.items.push(Item::Triangles {
                    tris: vec![[p0, p1, p2], [p2, p1, p3]],
                    transform: t,
                    color: fill,
                });
                if let Some(c) = stroke {
                    doc.items.push(Item::Hairline {
                        points: vec![p0, p1, p3, p2],
                        closed: true,
                        transform: t,
                        color: c,
                        opacity: stroke_opacity,
                    });
                }
            }
            "line" => {
                let a = DVec2::new(num_attr(&node, "x1", &loc)?, num_attr(&node, "y1", &loc)?);
                let b = DVec2::new(num_attr(&node, "x2", &loc)?, num_attr(&node, "y2", &loc)?);
                if let Some(c) = stroke {
                    doc.items.push(Item::Hairline {
                        points: vec![a, b],
                        closed: false,
                        transform: t,
                        color: c,
                        opacity: stroke_opacity,
                    });
                }
            }
            "polyline" => {
                let pts = points_attr(&node, "points", &loc)?;
                doc.items.push(Item::Hairline {
                    points: pts,
                    closed: false,
                    transform: t,
                    color: stroke.unwrap_or(Rgb::BLACK),
                    opacity: stroke_opacity,
                });
            }
            "polygon" => {
                let pts = points_attr(&node, "points", &loc)?;
                doc.items.push(Item::Triangles {
                    tris: ear_clip(&pts),
                    transform: t,
                    color: fill,
                });
                if let Some(c) = stroke {
                    doc.items.push(Item::Hairline {
                        points: pts,
                        closed: true,
                        transform: t,
                        color: c,
                        opacity: stroke_opacity,
                    });
                }
            }
            "colortri" | "texture" | "textri" => {
                course_element(&node, name, t, ctx, doc, textures, &loc, P)?;
            }
            "image" => {
                if let Some(item) = image_item(&node, t, ctx, doc, &loc, P)? {
                    doc.items.push(item);
                }
            }
            _ => {}
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hex_colors_as_the_course_reads_them() {
        assert_eq!(hex_color("#ff0000"), Rgb::new(1.0, 0.0, 0.0));
        assert_eq!(hex_color("000000"), Rgb::BLACK);
        assert_eq!(hex_color("none"), Rgb::BLACK);
        // "#f00" is the integer 0xf00, not red.
        assert_eq!(hex_color("#f00"), Rgb::new(0.0, 15.0 / 255.0, 0.0));
        for k in 0..=255u32 {
            let c = hex_color(&format!("#{k:02x}0000"));
            assert_eq!((c.r * 255.0) as u32, k, "truncation must round-trip");
        }
    }
}
