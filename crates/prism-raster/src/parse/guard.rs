//! The checks made on a standard SVG's XML before usvg reads it: an `<svg>` root; nesting
//! depth counted through references (`url(#id)`, `href="#id"`), so that no reading
//! recurses deeper than [`MAX_DEPTH`]; and the elements `use` copies would create, at most
//! [`MAX_USE_ELEMENTS`], each refused at the element where it passes its limit; no `href`
//! cycle among gradients, patterns and filters; and paths that text follows within
//! [`MAX_TEXT_PATH`].

use std::collections::HashMap;

use prism_math::{DVec2, Loc};
use roxmltree::{Document, Node, NodeId, ParsingOptions};

use super::common::{SvgError, MAX_DEPTH, MAX_USE_ELEMENTS};
use super::context::Source;
use crate::path::Segment;

/// The largest coordinate, in user units, of a path that text follows (`textPath`).
pub const MAX_TEXT_PATH: f64 = 1e9;

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
    let root = xml.root_element();
    if root.tag_name().name() != "svg" {
        return Err(SvgError::Element {
            at: Loc::line(&source.name, xml.text_pos_at(root.range().start).row),
            element: root.tag_name().name().to_string(),
            message: "expected the root element to be <svg>".into(),
        });
    }
    // usvg follows the `href` chains of gradients, patterns and filters until they come
    // back to where they started: a chain that enters a cycle elsewhere would never end,
    // so such a cycle is refused at the first element that enters it.
    let chained = |n: Node| {
        matches!(
            n.tag_name().name(),
            "linearGradient" | "radialGradient" | "pattern" | "filter"
        )
    };
    let href_of = |n: Node| -> Option<NodeId> {
        n.attributes()
            .find(|a| a.name() == "href")
            .and_then(|a| a.value().trim().strip_prefix('#'))
            .and_then(|id| ids.get(id).copied())
    };
    let mut state: HashMap<NodeId, u8> = HashMap::new(); // 1: on the walk, 2: done
    for start in xml.descendants().filter(|n| chained(*n)) {
        let mut walk = Vec::new();
        let mut cur = Some(start.id());
        while let Some(id) = cur {
            match state.get(&id) {
                Some(2) => break,
                Some(_) => {
                    let n = xml.get_node(id).unwrap_or(root);
                    return Err(SvgError::Element {
                        at: Loc::line(&source.name, xml.text_pos_at(n.range().start).row),
                        element: n.tag_name().name().to_string(),
                        message: "href leads back to this element".into(),
                    });
                }
                None => {}
            }
            state.insert(id, 1);
            walk.push(id);
            cur = xml
                .get_node(id)
                .filter(|n| chained(*n))
                .and_then(href_of)
                .filter(|t| *t != id && xml.get_node(*t).is_some_and(chained));
        }
        for id in walk {
            state.insert(id, 2);
        }
    }
    // Text on a path is laid out by measuring the path's length, which takes time growing
    // with its coordinates' magnitude: paths that text follows stay within MAX_TEXT_PATH.
    for n in xml.descendants().filter(|n| n.has_tag_name("textPath")) {
        let own = n.attribute("path");
        let linked = n
            .attributes()
            .find(|a| a.name() == "href")
            .and_then(|a| a.value().trim().strip_prefix('#'))
            .and_then(|id| ids.get(id))
            .and_then(|&t| xml.get_node(t))
            .and_then(|t| t.attribute("d"));
        for d in own.into_iter().chain(linked) {
            let (path, _) = super::pathdata::parse_path_data_prefix(d);
            let far = path.segments.iter().any(|seg| {
                let pts: &[DVec2] = match seg {
                    Segment::MoveTo(p) | Segment::LineTo(p) => std::slice::from_ref(p),
                    Segment::CubicTo(a, b, c) => &[*a, *b, *c],
                    Segment::Close => &[],
                };
                pts.iter()
                    .any(|p| !(p.x.abs() <= MAX_TEXT_PATH && p.y.abs() <= MAX_TEXT_PATH))
            });
            if far {
                return Err(SvgError::Element {
                    at: Loc::line(&source.name, xml.text_pos_at(n.range().start).row),
                    element: "textPath".into(),
                    message: format!(
                        "the path the text follows reaches beyond {MAX_TEXT_PATH:e} user units"
                    ),
                });
            }
        }
    }
    // Each element's successors: its child elements and what it references, each marked
    // with whether usvg copies it (children, and a `use` element's target).
    let succ = |n: Node| -> Vec<(NodeId, bool)> {
        let mut out: Vec<(NodeId, bool)> = n
            .children()
            .filter(|c| c.is_element())
            .map(|c| (c.id(), true))
            .collect();
        let is_use = n.tag_name().name() == "use";
        for a in n.attributes() {
            let v = a.value();
            if a.name() == "href" {
                if let Some(id) = v.trim().strip_prefix('#') {
                    out.extend(ids.get(id).map(|&t| (t, is_use)));
                }
            }
            let mut rest = v;
            while let Some(i) = rest.find("url(") {
                rest = &rest[i + 4..];
                let end = rest.find(')').unwrap_or(rest.len());
                let id = rest[..end].trim().trim_matches(['\'', '"']).trim();
                if let Some(id) = id.strip_prefix('#') {
                    out.extend(ids.get(id).map(|&t| (t, false)));
                }
                rest = &rest[end..];
            }
        }
        out
    };
    let located = |id: NodeId| {
        let n = xml.get_node(id).unwrap_or(root);
        (
            Loc::line(&source.name, xml.text_pos_at(n.range().start).row),
            n.tag_name().name().to_string(),
        )
    };
    // Depth-first over children and references with an explicit stack. For each finished
    // element, `done` holds the longest chain below it and the number of elements usvg
    // creates for it (`use` copies counted); an element still on the stack (a reference
    // cycle, which usvg skips) adds nothing.
    struct Frame {
        id: NodeId,
        next: Vec<(NodeId, bool)>,
        k: usize,
        depth: usize,
        size: u64,
    }
    let mut done: HashMap<NodeId, (usize, u64)> = HashMap::new();
    let mut on_stack: std::collections::HashSet<NodeId> = std::collections::HashSet::new();
    on_stack.insert(root.id());
    let mut stack = vec![Frame {
        id: root.id(),
        next: succ(root),
        k: 0,
        depth: 0,
        size: 1,
    }];
    while let Some(top) = stack.last_mut() {
        if top.k < top.next.len() {
            let (c, copied) = top.next[top.k];
            top.k += 1;
            if on_stack.contains(&c) {
                continue;
            }
            if let Some(&(d, n)) = done.get(&c) {
                top.depth = top.depth.max(d);
                if copied {
                    top.size = top.size.saturating_add(n);
                }
                if stack.len() + d > MAX_DEPTH {
                    let (at, element) = located(c);
                    return Err(SvgError::NestingLimit {
                        at,
                        element,
                        limit: MAX_DEPTH,
                    });
                }
                continue;
            }
            if stack.len() >= MAX_DEPTH {
                let (at, element) = located(c);
                return Err(SvgError::NestingLimit {
                    at,
                    element,
                    limit: MAX_DEPTH,
                });
            }
            on_stack.insert(c);
            let n = xml.get_node(c).unwrap_or(root);
            stack.push(Frame {
                id: c,
                next: succ(n),
                k: 0,
                depth: 0,
                size: 1,
            });
        } else {
            let f = stack.pop().expect("non-empty");
            on_stack.remove(&f.id);
            if f.size > MAX_USE_ELEMENTS as u64 {
                let (at, element) = located(f.id);
                return Err(SvgError::UseLimit {
                    at,
                    element,
                    limit: MAX_USE_ELEMENTS,
                });
            }
            done.insert(f.id, (f.depth + 1, f.size));
            if let Some(parent) = stack.last_mut() {
                parent.depth = parent.depth.max(f.depth + 1);
                let copied = parent.next[parent.k - 1].1;
                if copied {
                    parent.size = parent.size.saturating_add(f.size);
                }
            }
        }
    }
    Ok(xml)
}
