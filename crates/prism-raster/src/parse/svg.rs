//! The standard SVG dialect: presentation attributes and `style` declarations with
//! inheritance, units, `viewBox` with `preserveAspectRatio`, basic shapes, paths, images,
//! `use`, linear and radial gradients, and group opacity as offscreen layers.
//!
//! Not drawn (a warning is recorded once per kind): text, filters, clipping paths, masks,
//! markers and patterns. Elements of foreign namespaces (editor metadata) are skipped
//! silently.

use std::collections::HashMap;
use std::sync::Arc;

use prism_math::{DVec2, Loc, Rgb, Warning};
use roxmltree::Node;

use super::color::parse_color;
use super::common::{
    number_list, number_with_unit, parse_transform, ElementAt, PlainAttribute, SvgError, MAX_DEPTH,
    MAX_HREF_CHAIN, MAX_ITEMS, MAX_USE_ELEMENTS,
};
use super::context::{element_loc, Ctx};
use super::course::course_element;
use super::images::image_item;
use super::number::Precision;
use super::pathdata::parse_path_data_prefix;
use super::style::{apply_declarations, declarations, opacity_value, PaintSpec, Style};
use super::viewport::{length, view_box_transform, Axis, Viewport};
use crate::document::{Document, Gradient, GradientKind, Item, Mat3, Paint, Spread, Stop};
use crate::path::Path;

const P: Precision = Precision::F64;
const SVG_NS: &str = "http://www.w3.org/2000/svg";
const XLINK_NS: &str = "http://www.w3.org/1999/xlink";

struct Parser<'c, 'a> {
    ctx: &'c mut Ctx<'a>,
    doc: Document,
    ids: HashMap<&'a str, Node<'a, 'a>>,
    textures: HashMap<String, usize>,
}

pub(crate) fn parse<'a>(root: Node<'a, 'a>, ctx: &mut Ctx<'a>) -> Result<Document, SvgError> {
    let loc = element_loc(ctx, &root);
    let vb = root
        .attr("viewBox")
        .map(|s| number_list(s, P, &loc, "viewBox"))
        .transpose()?;
    let vb_size = vb.as_ref().filter(|v| v.len() == 4).map(|v| (v[2], v[3]));
    let dim = |name: &str, axis: Axis, fallback: f64| -> Result<f64, SvgError> {
        match root.attr(name) {
            Some(s) if s.trim().ends_with('%') => {
                let pc = number_with_unit(s, P, &loc, name)?.0 / 100.0;
                Ok(fallback * pc)
            }
            Some(s) => {
                let v = length(s, &loc, name, Viewport { w: 100.0, h: 100.0 }, axis)?;
                if v > 0.0 {
                    Ok(v)
                } else {
                    Err(loc.err(format!("{name}: expected a positive length, found {s:?}")))
                }
            }
            None => Ok(fallback),
        }
    };
    let width = dim("width", Axis::X, vb_size.map_or(100.0, |s| s.0))?;
    let height = dim("height", Axis::Y, vb_size.map_or(100.0, |s| s.1))?;
    let view_box_transform =
        view_box_transform(&root, &loc, width, height)?.unwrap_or(Mat3::IDENTITY);
    let xml = ctx.xml;
    let mut ids = HashMap::new();
    for n in xml.descendants().filter(Node::is_element) {
        if let Some(id) = n.attr("id") {
            ids.entry(id).or_insert(n);
        }
    }
    check_use_expansion(root, &ids, ctx)?;
    let mut p = Parser {
        ctx,
        doc: Document {
            width,
            height,
            view_box_transform,
            ..Document::default()
        },
        ids,
        textures: HashMap::new(),
    };
    let vp = vb_size.map_or(
        Viewport {
            w: width,
            h: height,
        },
        |(w, h)| Viewport { w, h },
    );
    let mut style = Style::default();
    let decls = declarations(&root);
    let (opacity, _, invalid) = apply_declarations(&mut style, &decls, &loc, vp);
    for (property, e) in invalid {
        p.warn_invalid(&property, &e);
    }
    let layer = opacity < 1.0;
    if layer {
        p.doc.items.push(Item::BeginLayer);
    }
    p.children(root, Mat3::IDENTITY, &style, vp, 1)?;
    if layer {
        p.doc.items.push(Item::EndLayer { opacity });
    }
    Ok(p.doc)
}

/// The id a `use` element refers to (`xlink:href` or `href`, without the `#`).
fn use_href<'a>(node: &Node<'a, 'a>) -> Option<&'a str> {
    let href = node
        .attribute((XLINK_NS, "href"))
        .or_else(|| node.attr("href"))?
        .trim();
    Some(href.strip_prefix('#').unwrap_or(href))
}

/// Whether the walk reads this element's children: groups, links, switches, nested `svg`.
fn is_container(node: &Node) -> bool {
    matches!(node.tag_name().name(), "g" | "a" | "switch" | "svg")
}

/// Counts, without expanding anything, the elements that `use` references would create,
/// and refuses a document that would create more than [`MAX_USE_ELEMENTS`] or whose
/// references lead back to themselves. It follows what [`Parser::element`] follows
/// (containers' children and `use` targets, a `symbol` by its children), each element once,
/// with an explicit stack: time and memory grow with the file, not with its expansion.
fn check_use_expansion<'a>(
    root: Node<'a, 'a>,
    ids: &HashMap<&'a str, Node<'a, 'a>>,
    ctx: &Ctx<'a>,
) -> Result<(), SvgError> {
    #[derive(Clone, Copy)]
    enum Mark {
        New,
        Open,
        /// Elements in the expansion (this one included) and elements created by `use` in it.
        Done(u64, u64),
    }
    let in_svg = |n: &Node| matches!(n.tag_name().namespace(), None | Some(SVG_NS));
    // What an element expands to, and whether that is a `use` copy.
    let expansion = |n: Node<'a, 'a>| -> (Vec<Node<'a, 'a>>, bool) {
        if !in_svg(&n) {
            return (Vec::new(), false);
        }
        if n.tag_name().name() == "use" {
            let target = use_href(&n).and_then(|id| ids.get(id)).copied();
            return match target {
                Some(t) if t.tag_name().name() == "symbol" => {
                    (t.children().filter(Node::is_element).collect(), true)
                }
                Some(t) => (vec![t], true),
                None => (Vec::new(), true),
            };
        }
        if n == root || is_container(&n) {
            return (n.children().filter(Node::is_element).collect(), false);
        }
        (Vec::new(), false)
    };
    let mut marks = vec![Mark::New; ctx.xml.descendants().count() + 1];
    // (element, the `use` that led to it, children already pushed)
    let mut stack = vec![(root, None::<Node<'a, 'a>>, false)];
    while let Some((n, via, expanded)) = stack.pop() {
        let i = n.id().get_usize();
        match (marks[i], expanded) {
            (Mark::Done(..), false) => {}
            (Mark::Open, false) => {
                let message = match via {
                    Some(u) if n.descendants().any(|d| d == u) => {
                        format!(
                            "href #{} refers to its own ancestor",
                            use_href(&u).unwrap_or("")
                        )
                    }
                    Some(u) => format!(
                        "href #{} leads back to itself through other references",
                        use_href(&u).unwrap_or("")
                    ),
                    None => "its use references lead back to its own ancestor".to_string(),
                };
                let loc = element_loc(ctx, &via.unwrap_or(n));
                return Err(loc.err(message));
            }
            (Mark::New, _) => {
                marks[i] = Mark::Open;
                stack.push((n, via, true));
                let (parts, is_use) = expansion(n);
                let via = if is_use { Some(n) } else { None };
                stack.extend(parts.into_iter().map(|c| (c, via, false)));
            }
            (_, true) => {
                let (parts, is_use) = expansion(n);
                let (mut size, mut created) = (0u64, 0u64);
                for c in parts {
                    if let Mark::Done(s, k) = marks[c.id().get_usize()] {
                        size = size.saturating_add(s);
                        created = created.saturating_add(k);
                    }
                }
                if is_use {
                    created = size;
                }
                if created > MAX_USE_ELEMENTS as u64 {
                    return Err(element_loc(ctx, &n).use_limit());
                }
                marks[i] = Mark::Done(size.saturating_add(1), created);
            }
        }
    }
    Ok(())
}

impl<'a> Parser<'_, 'a> {
    fn children(
        &mut self,
        parent: Node<'a, 'a>,
        ctm: Mat3,
        style: &Style,
        vp: Viewport,
        depth: usize,
    ) -> Result<(), SvgError> {
        for node in parent.children().filter(Node::is_element) {
            self.element(node, ctm, style, vp, depth)?;
        }
        Ok(())
    }

    fn warn(&mut self, key: &str, warning: Warning) {
        self.ctx.warn_once(&mut self.doc, key, warning);
    }

    /// One warning per property of the file whose value is invalid (and treated as absent).
    fn warn_invalid(&mut self, property: &str, e: &SvgError) {
        self.warn(
            &format!("invalid:{property}"),
            Warning::new(format!("{e}; treated as absent (warned once per property)")),
        );
    }

    fn element(
        &mut self,
        node: Node<'a, 'a>,
        ctm: Mat3,
        parent_style: &Style,
        vp: Viewport,
        depth: usize,
    ) -> Result<(), SvgError> {
        let ctx = &*self.ctx;
        let loc = element_loc(ctx, &node);
        let loc = ElementAt {
            file: loc.file,
            line: loc.line,
            element: loc.element,
        };
        // Copy the location out of the borrow of ctx.
        let (file, line, elem) = (loc.file.to_string(), loc.line, loc.element.to_string());
        let loc = ElementAt {
            file: &file,
            line,
            element: &elem,
        };
        if depth >= MAX_DEPTH {
            return Err(loc.nesting_limit());
        }
        if self.doc.items.len() > MAX_ITEMS {
            return Err(loc.items_limit());
        }
        match node.tag_name().namespace() {
            None | Some(SVG_NS) => {}
            Some(_) => return Ok(()),
        }
        let name = node.tag_name().name();
        match name {
            "defs" | "symbol" | "linearGradient" | "radialGradient" | "stop" | "title" | "desc"
            | "metadata" | "style" | "script" | "clipPath" | "mask" | "pattern" | "marker"
            | "filter" => return Ok(()),
            _ => {}
        }
        let mut style = parent_style.clone();
        let (opacity, display, invalid) =
            apply_declarations(&mut style, &declarations(&node), &loc, vp);
        for (property, e) in invalid {
            self.warn_invalid(&property, &e);
        }
        if !display {
            return Ok(());
        }
        for unsupported in ["clip-path", "mask", "filter"] {
            if node.attr(unsupported).is_some_and(|v| v.trim() != "none") {
                self.warn(
                    unsupported,
                    Warning::at(
                        Loc::line(&file, line),
                        format!("{elem}: {unsupported} is not supported; drawn without it"),
                    ),
                );
            }
        }
        // An invalid transform is treated as absent, as SVG 2 has it.
        let mut t = match node
            .attr("transform")
            .map(|s| parse_transform(s, P, &loc, false))
        {
            Some(Ok(m)) => ctm.mul(&m),
            Some(Err(e)) => {
                self.warn_invalid("transform", &e);
                ctm
            }
            None => ctm,
        };
        let num = |attr: &str, axis: Axis| -> Result<f64, SvgError> {
            node.attr(attr)
                .map_or(Ok(0.0), |s| length(s, &loc, attr, vp, axis))
        };
        let path = match name {
            "g" | "a" | "switch" => {
                return self.group(node, t, &style, opacity, vp, depth);
            }
            "svg" => {
                let (x, y) = (num("x", Axis::X)?, num("y", Axis::Y)?);
                t = t.mul(&Mat3::translate(x, y));
                let w = node
                    .attr("width")
                    .map_or(Ok(vp.w), |s| length(s, &loc, "width", vp, Axis::X))?;
                let h = node
                    .attr("height")
                    .map_or(Ok(vp.h), |s| length(s, &loc, "height", vp, Axis::Y))?;
                let mut inner = vp;
                if let Some(m) = view_box_transform(&node, &loc, w, h)? {
                    t = t.mul(&m);
                    let v = number_list(node.attr("viewBox").unwrap_or(""), P, &loc, "viewBox")?;
                    inner = Viewport { w: v[2], h: v[3] };
                }
                return self.group(node, t, &style, opacity, inner, depth);
            }
            "use" => {
                let href = node
                    .attribute((XLINK_NS, "href"))
                    .or_else(|| node.attr("href"))
                    .ok_or_else(|| loc.err("expected an href attribute"))?;
                let id = href.trim().strip_prefix('#').unwrap_or(href.trim());
                let Some(&target) = self.ids.get(id) else {
                    self.warn(
                        &format!("use#{id}"),
                        Warning::at(
                            Loc::line(&file, line),
                            format!("use: no element with id {id:?}; skipped"),
                        ),
                    );
                    return Ok(());
                };
                // check_use_expansion has refused every reference cycle before the walk.
                let (x, y) = (num("x", Axis::X)?, num("y", Axis::Y)?);
                let t = t.mul(&Mat3::translate(x, y));
                let layer = opacity < 1.0;
                if layer {
                    self.doc.items.push(Item::BeginLayer);
                }
                if target.tag_name().name() == "symbol" {
                    self.children(target, t, &style, vp, depth + 1)?;
                } else {
                    self.element(target, t, &style, vp, depth + 1)?;
                }
                if layer {
                    self.doc.items.push(Item::EndLayer { opacity });
                }
                return Ok(());
            }
            "rect" => {
                let (x, y) = (num("x", Axis::X)?, num("y", Axis::Y)?);
                let (w, h) = (num("width", Axis::X)?, num("height", Axis::Y)?);
                if w <= 0.0 || h <= 0.0 {
                    return Ok(());
                }
                let rx_attr = node
                    .attr("rx")
                    .map(|s| length(s, &loc, "rx", vp, Axis::X))
                    .transpose()?;
                let ry_attr = node
                    .attr("ry")
                    .map(|s| length(s, &loc, "ry", vp, Axis::Y))
                    .transpose()?;
                let (rx, ry) = match (rx_attr, ry_attr) {
                    (None, None) => (0.0, 0.0),
                    (Some(r), None) | (None, Some(r)) => (r, r),
                    (Some(a), Some(b)) => (a, b),
                };
                let (rx, ry) = (rx.clamp(0.0, w / 2.0), ry.clamp(0.0, h / 2.0));
                let mut p = Path::default();
                if rx > 0.0 && ry > 0.0 {
                    let d = |a: f64, b: f64| DVec2::new(a, b);
                    p.move_to(d(x + rx, y));
                    p.line_to(d(x + w - rx, y));
                    p.arc_to(d(x + w - rx, y), rx, ry, 0.0, false, true, d(x + w, y + ry));
                    p.line_to(d(x + w, y + h - ry));
                    p.arc_to(
                        d(x + w, y + h - ry),
                        rx,
                        ry,
                        0.0,
                        false,
                        true,
                        d(x + w - rx, y + h),
                    );
                    p.line_to(d(x + rx, y + h));
                    p.arc_to(d(x + rx, y + h), rx, ry, 0.0, false, true, d(x, y + h - ry));
                    p.line_to(d(x, y + ry));
                    p.arc_to(d(x, y + ry), rx, ry, 0.0, false, true, d(x + rx, y));
                    p.close();
                } else {
                    p = Path::polygon(
                        &[
                            DVec2::new(x, y),
                            DVec2::new(x + w, y),
                            DVec2::new(x + w, y + h),
                            DVec2::new(x, y + h),
                        ],
                        true,
                    );
                }
                p
            }
            "circle" | "ellipse" => {
                let c = DVec2::new(num("cx", Axis::X)?, num("cy", Axis::Y)?);
                let (rx, ry) = if name == "circle" {
                    let r = num("r", Axis::Diag)?;
                    (r, r)
                } else {
                    (num("rx", Axis::X)?, num("ry", Axis::Y)?)
                };
                if rx <= 0.0 || ry <= 0.0 {
                    return Ok(());
                }
                Path::ellipse(c, rx, ry)
            }
            "line" => {
                let a = DVec2::new(num("x1", Axis::X)?, num("y1", Axis::Y)?);
                let b = DVec2::new(num("x2", Axis::X)?, num("y2", Axis::Y)?);
                Path::polygon(&[a, b], false)
            }
            "polyline" | "polygon" => {
                let l = number_list(node.attr("points").unwrap_or(""), P, &loc, "points")?;
                if l.len() % 2 != 0 {
                    return Err(loc.err(format!(
                        "points: expected x,y pairs, found {} numbers",
                        l.len()
                    )));
                }
                let pts: Vec<DVec2> = l.chunks_exact(2).map(|c| DVec2::new(c[0], c[1])).collect();
                Path::polygon(&pts, name == "polygon")
            }
            "path" => {
                // Drawn up to the first error, as the specification has it.
                let (path, error) = parse_path_data_prefix(node.attr("d").unwrap_or(""));
                if let Some(e) = error {
                    self.warn(
                        "invalid:d",
                        Warning::new(format!("{}; drawn up to the error", loc.path_data(e))),
                    );
                }
                path
            }
            "image" => {
                if !style.visible {
                    return Ok(());
                }
                if let Some(Item::Image {
                    texture,
                    rect,
                    transform,
                    ..
                }) = image_item(&node, t, self.ctx, &mut self.doc, &loc, P)?
                {
                    self.doc.items.push(Item::Image {
                        texture,
                        rect,
                        transform,
                        opacity,
                    });
                }
                return Ok(());
            }
            "colortri" | "texture" | "textri" => {
                course_element(
                    &node,
                    name,
                    t,
                    self.ctx,
                    &mut self.doc,
                    &mut self.textures,
                    &loc,
                    P,
                )?;
                return Ok(());
            }
            "text" | "tspan" | "textPath" => {
                self.warn(
                    "text",
                    Warning::at(
                        Loc::line(&file, line),
                        format!("{name}: text is not supported; skipped"),
                    ),
                );
                return Ok(());
            }
            other => {
                self.warn(
                    &format!("elem:{other}"),
                    Warning::at(
                        Loc::line(&file, line),
                        format!("{other}: unknown element; skipped"),
                    ),
                );
                return Ok(());
            }
        };
        if !path.is_finite() {
            return Err(loc.err("coordinates must be finite"));
        }
        if !style.visible || path.segments.is_empty() {
            return Ok(());
        }
        self.shape(path, t, &style, opacity, name, &loc)
    }

    fn group(
        &mut self,
        node: Node<'a, 'a>,
        t: Mat3,
        style: &Style,
        opacity: f32,
        vp: Viewport,
        depth: usize,
    ) -> Result<(), SvgError> {
        let layer = opacity < 1.0;
        if layer {
            self.doc.items.push(Item::BeginLayer);
        }
        self.children(node, t, style, vp, depth + 1)?;
        if layer {
            self.doc.items.push(Item::EndLayer { opacity });
        }
        Ok(())
    }

    fn shape(
        &mut self,
        path: Path,
        t: Mat3,
        style: &Style,
        opacity: f32,
        name: &str,
        loc: &ElementAt,
    ) -> Result<(), SvgError> {
        let fillable = name != "line";
        let fill = if fillable {
            self.resolve_paint(&style.fill, style, &path, loc)?
        } else {
            None
        };
        let stroke = if style.stroke.width > 0.0 {
            self.resolve_paint(&style.stroke_paint, style, &path, loc)?
        } else {
            None
        };
        let both = fill.is_some() && stroke.is_some();
        let layer = both && opacity < 1.0;
        let inner = if layer { 1.0 } else { opacity };
        if layer {
            self.doc.items.push(Item::BeginLayer);
        }
        if let Some((paint, a)) = fill {
            self.doc.items.push(Item::Fill {
                path: path.clone(),
                transform: t,
                rule: style.fill_rule,
                paint,
                opacity: a * style.fill_opacity * inner,
            });
        }
        if let Some((paint, a)) = stroke {
            self.doc.items.push(Item::Stroke {
                path,
                transform: t,
                style: style.stroke.clone(),
                paint,
                opacity: a * style.stroke_opacity * inner,
            });
        }
        if layer {
            self.doc.items.push(Item::EndLayer { opacity });
        }
        Ok(())
    }

    fn resolve_paint(
        &mut self,
        spec: &PaintSpec,
        style: &Style,
        path: &Path,
        loc: &ElementAt,
    ) -> Result<Option<(Paint, f32)>, SvgError> {
        Ok(match spec {
            PaintSpec::None => None,
            PaintSpec::Color(c, a) => Some((Paint::Solid(*c), *a)),
            PaintSpec::CurrentColor => Some((Paint::Solid(style.color), 1.0)),
            PaintSpec::Url(id, fallback) => match self.gradient(id, path, loc)? {
                Some(g) => {
                    if g.stops.len() == 1 {
                        Some((Paint::Solid(g.stops[0].color), g.stops[0].opacity))
                    } else {
                        Some((Paint::Gradient(g), 1.0))
                    }
                }
                None => match fallback {
                    Some(fb) => self.resolve_paint(fb, style, path, loc)?,
                    None => {
                        if !self.ids.contains_key(id.as_str()) {
                            let msg = Warning::at(
                                Loc::line(loc.file, loc.line),
                                format!("{}: paint url(#{id}) not found; not painted", loc.element),
                            );
                            self.warn(&format!("paint#{id}"), msg);
                        }
                        None
                    }
                },
            },
        })
    }

    /// Resolves a gradient by id for an element whose local path is `path`, following
    /// `href` chains for stops and attributes.
    fn gradient(
        &mut self,
        id: &str,
        path: &Path,
        loc: &ElementAt,
    ) -> Result<Option<Arc<Gradient>>, SvgError> {
        let Some(&node) = self.ids.get(id) else {
            return Ok(None);
        };
        let kind = node.tag_name().name();
        if kind != "linearGradient" && kind != "radialGradient" {
            if kind == "pattern" {
                self.warn(
                    "pattern",
                    Warning::at(
                        Loc::line(loc.file, loc.line),
                        "pattern paint is not supported; not painted",
                    ),
                );
            }
            return Ok(None);
        }
        // The chain of referenced gradients, nearest first; a link back into it ends it.
        let mut chain = vec![node];
        loop {
            let last = chain[chain.len() - 1];
            let href = last
                .attribute((XLINK_NS, "href"))
                .or_else(|| last.attr("href"));
            match href.and_then(|h| self.ids.get(h.trim().trim_start_matches('#'))) {
                Some(&n) if !chain.contains(&n) => {
                    if chain.len() == MAX_HREF_CHAIN {
                        return Err(element_loc(self.ctx, &node).href_chain_limit());
                    }
                    chain.push(n);
                }
                _ => break,
            }
        }
        let attr = |name: &str| chain.iter().find_map(|n| n.attr(name));
        let gloc = element_loc(self.ctx, &node);
        let (gfile, gline, gelem) = (gloc.file.to_string(), gloc.line, gloc.element.to_string());
        let gloc = ElementAt {
            file: &gfile,
            line: gline,
            element: &gelem,
        };
        let user_space = attr("gradientUnits") == Some("userSpaceOnUse");
        let vp = Viewport {
            w: self.doc.width,
            h: self.doc.height,
        };
        let coord = |name: &str, default: &str, axis: Axis| -> Result<f64, SvgError> {
            let s = attr(name).unwrap_or(default);
            if !user_space {
                let (v, unit) = number_with_unit(s, P, &gloc, name)?;
                return Ok(if unit == "%" { v / 100.0 } else { v });
            }
            length(s, &gloc, name, vp, axis)
        };
        let stops_node = chain
            .iter()
            .find(|n| n.children().any(|c| c.tag_name().name() == "stop"));
        let mut stops: Vec<Stop> = Vec::new();
        if let Some(sn) = stops_node {
            for s in sn.children().filter(|c| c.tag_name().name() == "stop") {
                let sl = element_loc(self.ctx, &s);
                let (sfile, sline) = (sl.file.to_string(), sl.line);
                let sloc = ElementAt {
                    file: &sfile,
                    line: sline,
                    element: "stop",
                };
                let decls = declarations(&s);
                let get = |k: &str| {
                    decls
                        .iter()
                        .rev()
                        .find(|(n, _)| n == k)
                        .map(|(_, v)| v.as_str())
                };
                let offset =
                    get("offset").map_or(Ok(0.0), |v| opacity_value(v, &sloc, "offset"))?;
                let (color, ca) = match get("stop-color") {
                    None => (Rgb::BLACK, 1.0),
                    Some(v) => parse_color(v).ok_or_else(|| {
                        sloc.err(format!("stop-color: expected a colour, found {v:?}"))
                    })?,
                };
                let op = get("stop-opacity")
                    .map_or(Ok(1.0), |v| opacity_value(v, &sloc, "stop-opacity"))?;
                let prev = stops.last().map_or(0.0, |s| s.offset);
                stops.push(Stop {
                    offset: offset.max(prev),
                    color,
                    opacity: op * ca,
                });
            }
        }
        if stops.is_empty() {
            return Ok(None);
        }
        let spread = match attr("spreadMethod") {
            Some("reflect") => Spread::Reflect,
            Some("repeat") => Spread::Repeat,
            _ => Spread::Pad,
        };
        let gt = match attr("gradientTransform") {
            Some(s) => parse_transform(s, P, &gloc, false)?,
            None => Mat3::IDENTITY,
        };
        let units = if user_space {
            Mat3::IDENTITY
        } else {
            // objectBoundingBox: map the unit square onto the element's bounding box.
            let pts: Vec<DVec2> = path
                .flatten(0.01)
                .into_iter()
                .flat_map(|l| l.points)
                .collect();
            let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
            for p in pts {
                lo = lo.min(p);
                hi = hi.max(p);
            }
            let size = hi - lo;
            if !(size.x > 0.0 && size.y > 0.0) {
                return Ok(None);
            }
            Mat3::translate(lo.x, lo.y).mul(&Mat3::scale(size.x, size.y))
        };
        let kind = if kind == "linearGradient" {
            GradientKind::Linear {
                start: DVec2::new(coord("x1", "0%", Axis::X)?, coord("y1", "0%", Axis::Y)?),
                end: DVec2::new(coord("x2", "100%", Axis::X)?, coord("y2", "0%", Axis::Y)?),
            }
        } else {
            let center = DVec2::new(coord("cx", "50%", Axis::X)?, coord("cy", "50%", Axis::Y)?);
            let radius = coord("r", "50%", Axis::Diag)?;
            let focus = DVec2::new(
                attr("fx").map_or(Ok(center.x), |_| coord("fx", "50%", Axis::X))?,
                attr("fy").map_or(Ok(center.y), |_| coord("fy", "50%", Axis::Y))?,
            );
            if radius <= 0.0 {
                let last = stops[stops.len() - 1];
                stops = vec![last];
            }
            GradientKind::Radial {
                center,
                radius,
                focus,
            }
        };
        Ok(Some(Arc::new(Gradient {
            kind,
            stops,
            spread,
            transform: units.mul(&gt),
        })))
    }
}
