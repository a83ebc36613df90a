//! The course's own elements, read in both dialects: `colortri`, `texture` and `textri`.

use std::collections::HashMap;

use prism_image::UvConvention;
use prism_math::{DVec2, Rgb, Vec2};
use roxmltree::Node;

use super::common::{number_list, ElementAt, PlainAttribute, SvgError};
use super::context::Ctx;
use super::images::load_texture;
use super::number::Precision;
use crate::document::{Document, Item, Mat3};

/// Exactly `n` numbers from attribute `attr`.
fn exact_numbers(
    node: &Node,
    attr: &str,
    n: usize,
    loc: &ElementAt,
    p: Precision,
) -> Result<Vec<f64>, SvgError> {
    let v = number_list(node.attr(attr).unwrap_or(""), p, loc, attr)?;
    if v.len() != n {
        return Err(loc.err(format!("{attr}: expected {n} numbers, found {}", v.len())));
    }
    Ok(v)
}

/// Reads one of the course's custom elements into `doc`: `colortri` (points and r g b a
/// colours per vertex), `texture` (registers an image file under `texid`, alpha dropped,
/// edge-centred uvs) and `textri` (points, uvs and a `texid`). Returns false for any other
/// element.
#[allow(clippy::too_many_arguments)]
pub(crate) fn course_element(
    node: &Node,
    name: &str,
    transform: Mat3,
    ctx: &Ctx,
    doc: &mut Document,
    textures: &mut HashMap<String, usize>,
    loc: &ElementAt,
    p: Precision,
) -> Result<bool, SvgError> {
    let tri = |v: &[f64]| {
        [
            DVec2::new(v[0], v[1]),
            DVec2::new(v[2], v[3]),
            DVec2::new(v[4], v[5]),
        ]
    };
    match name {
        "colortri" => {
            let points = tri(&exact_numbers(node, "points", 6, loc, p)?);
            let c = exact_numbers(node, "colors", 12, loc, p)?;
            let col =
                |i: usize| Rgb::new(c[4 * i] as f32, c[4 * i + 1] as f32, c[4 * i + 2] as f32);
            doc.items.push(Item::ColorTri {
                points,
                colors: [col(0), col(1), col(2)],
                transform,
            });
        }
        "texture" => {
            let id = node
                .attr("texid")
                .ok_or_else(|| loc.err("expected a texid attribute"))?;
            let file = node
                .attr("filename")
                .ok_or_else(|| loc.err("expected a filename attribute"))?;
            let idx = load_texture(ctx, doc, file, loc, UvConvention::EdgeCenters)?;
            textures.insert(id.to_string(), idx);
        }
        "textri" => {
            let points = tri(&exact_numbers(node, "points", 6, loc, p)?);
            let uv = exact_numbers(node, "uvs", 6, loc, p)?;
            let id = node.attr("texid").unwrap_or("");
            let texture = *textures.get(id).ok_or_else(|| {
                loc.err(format!(
                    "texid {id:?}: expected the id of an earlier <texture>"
                ))
            })?;
            let f = |i: usize| Vec2::new(uv[2 * i] as f32, uv[2 * i + 1] as f32);
            doc.items.push(Item::TexTri {
                points,
                uvs: [f(0), f(1), f(2)],
                texture,
                transform,
            });
        }
        _ => return Ok(false),
    }
    Ok(true)
}
