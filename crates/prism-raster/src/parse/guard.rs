//! The checks made on a standard SVG's XML before usvg reads it: nesting depth counted
//! through references (`url(#id)`, `href="#id"`), so that no reading recurses deeper than
//! [`MAX_DEPTH`].

use std::collections::HashMap;

use prism_math::Loc;
use roxmltree::{Document, Node, NodeId, ParsingOptions};

use super::common::{SvgError, MAX_DEPTH};
use super::context::Source;

/// Parses the XML and checks its nesting.
///
/// # Errors
/// [`SvgError::Xml`] for malformed XML, [`SvgError::NestingLimit`] for elements nested,
/// directly or through references, deeper than [`MAX_DEPTH`].
pub(crate) fn check_nesting<'a>(text: &'a str, source: &Source) -> Result<Document<'a>, SvgError> {
    let opts = ParsingOptions {
        allow_dtd: true,
        nodes_limit: 50_000_000,
        ..ParsingOptions::default()
    };
    let xml = Document::parse_with_options(text, opts).map_err(|e| SvgError::Xml {
        at: Loc::line(&source.name, e.pos().row),
        source: e,
    })?;
    let ids: HashMap<&str, NodeId> = xml
        .descendants()
        .filter_map(|n| Some((n.attribute("id")?, n.id())))
        .collect();
    let mut refs: Vec<NodeId> = Vec::new();
    let references = |n: Node, out: &mut Vec<NodeId>| {
        out.clear();
        for a in n.attributes() {
            let v = a.value();
            if a.name() == "href" {
                if let Some(id) = v.trim().strip_prefix('#') {
                    out.extend(ids.get(id));
                }
            }
            let mut rest = v;
            while let Some(i) = rest.find("url(") {
                rest = &rest[i + 4..];
                let end = rest.find(')').unwrap_or(rest.len());
                let id = rest[..end].trim().trim_matches(['\'', '"']).trim();
                if let Some(id) = id.strip_prefix('#') {
                    out.extend(ids.get(id));
                }
                rest = &rest[end..];
            }
        }
    };
    // Depth-first over children and references with an explicit stack; `depth` holds the
    // longest chain found below each finished element, and an element still on the stack
    // (a reference cycle, which usvg skips) adds nothing.
    const ON_STACK: u32 = u32::MAX;
    let mut depth: HashMap<NodeId, u32> = HashMap::new();
    let mut stack: Vec<(NodeId, Vec<NodeId>, usize, u32)> = Vec::new();
    let root = xml.root_element();
    depth.insert(root.id(), ON_STACK);
    let succ = |n: Node, refs: &mut Vec<NodeId>| -> Vec<NodeId> {
        references(n, refs);
        let mut s: Vec<NodeId> = n
            .children()
            .filter(|c| c.is_element())
            .map(|c| c.id())
            .collect();
        s.extend(refs.iter().copied());
        s
    };
    stack.push((root.id(), succ(root, &mut refs), 0, 0));
    while let Some(top) = stack.last_mut() {
        let (id, next, k, best) = (top.0, &top.1, top.2, top.3);
        if k < next.len() {
            let c = next[k];
            top.2 += 1;
            let known = depth.get(&c).copied();
            if let Some(d) = known.filter(|&d| d != ON_STACK) {
                top.3 = best.max(d);
            }
            let reach = match known {
                None => 1,
                Some(ON_STACK) => 0,
                Some(d) => d as usize,
            };
            match known {
                Some(_) if stack.len() + reach <= MAX_DEPTH => {}
                _ => {
                    if stack.len() + reach > MAX_DEPTH {
                        let n = xml.get_node(c).unwrap_or(root);
                        let row = xml.text_pos_at(n.range().start).row;
                        return Err(SvgError::NestingLimit {
                            at: Loc::line(&source.name, row),
                            element: n.tag_name().name().to_string(),
                            limit: MAX_DEPTH,
                        });
                    }
                    if known.is_some() {
                        continue;
                    }
                    depth.insert(c, ON_STACK);
                    let n = xml.get_node(c).unwrap_or(root);
                    let s = succ(n, &mut refs);
                    stack.push((c, s, 0, 0));
                }
            }
        } else {
            depth.insert(id, best + 1);
            stack.pop();
            if let Some(parent) = stack.last_mut() {
                parent.3 = parent.3.max(best + 1);
            }
        }
    }
    Ok(xml)
}
