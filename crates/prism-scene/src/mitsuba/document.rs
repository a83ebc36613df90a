//! A Mitsuba 3 scene file as a tree of plugin objects: `<include>`s read in place,
//! `<default>`s and `-D` values substituted for `$name`, properties typed, transforms
//! composed, and `<ref id>`s resolved to the objects they name.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use prism_math::glam::{DMat4, DVec3};
use prism_math::Loc;
use roxmltree::Node as XmlNode;

use super::limits::{MAX_INCLUDE_DEPTH, MAX_MITSUBA_BYTES, MAX_OBJECTS, MAX_SCENE_FILES};
use super::transform::read_transform;
use super::values::{colour, number, triple};
use crate::error::SceneError;

/// A property's value.
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    /// `<integer>`.
    Integer(i64),
    /// `<float>`.
    Float(f64),
    /// `<boolean>`.
    Boolean(bool),
    /// `<string>`.
    String(String),
    /// `<rgb>`, or a constant `<spectrum>`.
    Rgb([f64; 3]),
    /// `<point>`.
    Point(DVec3),
    /// `<vector>`.
    Vector(DVec3),
    /// `<transform>`: the operations composed in document order.
    Transform(DMat4),
}

impl Value {
    /// The value's element name, for messages.
    #[must_use]
    pub fn kind(&self) -> &'static str {
        match self {
            Value::Integer(_) => "integer",
            Value::Float(_) => "float",
            Value::Boolean(_) => "boolean",
            Value::String(_) => "string",
            Value::Rgb(_) => "rgb",
            Value::Point(_) => "point",
            Value::Vector(_) => "vector",
            Value::Transform(_) => "transform",
        }
    }
}

/// One plugin object: `<shape type="obj" id="...">` and what it holds.
#[derive(Clone, Debug, PartialEq)]
pub struct Object {
    /// The element's tag: `shape`, `bsdf`, `emitter`, `sensor`, `film`, ...
    pub tag: String,
    /// The plugin's `type`.
    pub kind: String,
    /// The `id`, if any.
    pub id: Option<String>,
    /// Where its start tag is.
    pub at: Loc,
    /// The named properties, in document order (a later one of a name replaces an earlier).
    pub props: Vec<Property>,
    /// The nested objects and references, in document order: the `name` they were given,
    /// if any, and the index of the object in [`Document::objects`].
    pub children: Vec<(Option<String>, usize)>,
}

/// A named property of an object.
#[derive(Clone, Debug, PartialEq)]
pub struct Property {
    /// Its `name`.
    pub name: String,
    /// Its value.
    pub value: Value,
    /// Where it is written.
    pub at: Loc,
}

impl Object {
    /// `type="kind"`, for messages (which name the element `<tag>` before it).
    #[must_use]
    pub fn label(&self) -> String {
        format!("type=\"{}\"", self.kind)
    }

    /// The property `name`, if given (the last one written).
    #[must_use]
    pub fn prop(&self, name: &str) -> Option<&Property> {
        self.props.iter().rev().find(|p| p.name == name)
    }
}

/// A scene file read: every object, the root (`<scene>`) first.
#[derive(Clone, Debug, PartialEq)]
pub struct Document {
    /// The objects; index 0 is the `<scene>`.
    pub objects: Vec<Object>,
    /// The scene file's folder, against which file names are resolved.
    pub folder: PathBuf,
    /// Further folders file names are looked for in (`<path value>`), in order.
    pub search: Vec<PathBuf>,
    /// The XML files read: the scene and its includes.
    pub files: Vec<PathBuf>,
}

impl Document {
    /// Where file `name` is: under the scene's folder if it is there, else under the first
    /// search folder that holds it (else under the scene's folder, for the message).
    #[must_use]
    pub fn resolve(&self, name: &str) -> PathBuf {
        let here = self.folder.join(name);
        if here.exists() {
            return here;
        }
        self.search
            .iter()
            .map(|f| f.join(name))
            .find(|p| p.exists())
            .unwrap_or(here)
    }
}

/// The tags that make plugin objects.
const OBJECT_TAGS: [&str; 12] = [
    "shape",
    "bsdf",
    "emitter",
    "sensor",
    "film",
    "rfilter",
    "sampler",
    "integrator",
    "texture",
    "medium",
    "phase",
    "volume",
];

/// The tags that make properties.
const PROPERTY_TAGS: [&str; 9] = [
    "integer",
    "float",
    "boolean",
    "string",
    "rgb",
    "spectrum",
    "point",
    "vector",
    "transform",
];

/// One file of the scene: its name for messages, its folder and its text.
struct Source {
    name: String,
    folder: PathBuf,
    text: String,
}

/// Reads the scene file `path` and every file it includes; `defines` are `-D name=value`
/// settings, which win over the file's `<default>`s.
///
/// # Errors
/// [`SceneError::Io`] for a file that cannot be read, [`SceneError::Xml`] for malformed XML,
/// and [`SceneError::Element`], naming file, line and element, for anything else: an
/// unknown tag, a malformed value, a `$name` with no value, an include chain past
/// [`MAX_INCLUDE_DEPTH`] or more than [`MAX_SCENE_FILES`] files, a reference to no object.
pub fn read_document(path: &Path, defines: &[(String, String)]) -> Result<Document, SceneError> {
    let mut reader = Reader {
        search: Vec::new(),
        files: Vec::new(),
        sources: Vec::new(),
        bytes: 0,
        objects: Vec::new(),
        ids: HashMap::new(),
        params: defines.iter().cloned().collect(),
        pending_refs: Vec::new(),
    };
    let main = reader.load(path, None)?;
    let root_file = reader.sources[main].name.clone();
    reader.objects.push(Object {
        tag: "scene".into(),
        kind: "scene".into(),
        id: None,
        at: Loc::line(&root_file, 1),
        props: Vec::new(),
        children: Vec::new(),
    });
    reader.walk_file(main, 0, 0)?;
    reader.resolve_refs()?;
    Ok(Document {
        objects: reader.objects,
        folder: reader.sources[main].folder.clone(),
        search: reader.search,
        files: reader.files,
    })
}

/// The reader's state while it walks the files.
struct Reader {
    sources: Vec<Source>,
    bytes: u64,
    objects: Vec<Object>,
    ids: HashMap<String, usize>,
    params: HashMap<String, String>,
    /// `<ref>`s met before the object they name: (parent, slot in its children, id, where).
    pending_refs: Vec<(usize, usize, String, Loc)>,
    /// The `<path>` folders met so far.
    search: Vec<PathBuf>,
    /// The files read so far.
    files: Vec<PathBuf>,
}

/// A located error at `node` of `file`.
fn element_error(
    lines: &prism_math::LineIndex,
    file: &str,
    node: XmlNode,
    message: impl Into<String>,
) -> SceneError {
    SceneError::Element {
        at: Loc::line(file, lines.line(node.range().start)),
        element: node.tag_name().name().to_string(),
        message: message.into(),
    }
}

impl Reader {
    /// Reads `path` (relative to the including file's folder) into a new source.
    fn load(&mut self, path: &Path, from: Option<(&str, u32)>) -> Result<usize, SceneError> {
        if self.sources.len() >= MAX_SCENE_FILES {
            let (file, line) = from.unwrap_or(("", 0));
            return Err(SceneError::Element {
                at: Loc::line(file, line),
                element: "include".into(),
                message: format!("more than {MAX_SCENE_FILES} files in one scene"),
            });
        }
        let name = path.display().to_string();
        self.files.push(path.to_path_buf());
        let io = |e: std::io::Error| SceneError::Io {
            path: name.clone(),
            source: std::sync::Arc::new(e),
        };
        let text = prism_math::limits::read_input_text(path, MAX_MITSUBA_BYTES).map_err(io)?;
        self.bytes += text.len() as u64;
        prism_math::limits::check_memory(self.bytes.saturating_mul(8)).map_err(|e| {
            SceneError::Element {
                at: Loc::line(&name, 1),
                element: "scene".into(),
                message: format!("the scene's files: {e}"),
            }
        })?;
        let folder = path.parent().map_or_else(PathBuf::new, Path::to_path_buf);
        self.sources.push(Source { name, folder, text });
        Ok(self.sources.len() - 1)
    }

    /// Walks the `<scene>` of source `src` into object `parent`; `depth` counts includes.
    fn walk_file(&mut self, src: usize, parent: usize, depth: usize) -> Result<(), SceneError> {
        // The text is moved out while it is borrowed by the XML tree, and put back after.
        let text = std::mem::take(&mut self.sources[src].text);
        let file = self.sources[src].name.clone();
        let result = self.walk_text(&text, &file, src, parent, depth);
        self.sources[src].text = text;
        result
    }

    fn walk_text(
        &mut self,
        text: &str,
        file: &str,
        src: usize,
        parent: usize,
        depth: usize,
    ) -> Result<(), SceneError> {
        let xml = roxmltree::Document::parse(text).map_err(|e| SceneError::Xml {
            file: file.to_string(),
            source: e,
        })?;
        let lines = prism_math::LineIndex::new(text);
        let root = xml.root_element();
        if root.tag_name().name() != "scene" {
            return Err(element_error(
                &lines,
                file,
                root,
                "expected a <scene> root element",
            ));
        }
        let version = root.attribute("version").unwrap_or("");
        let major = version
            .split('.')
            .next()
            .and_then(|m| m.parse::<u32>().ok());
        if !matches!(major, Some(2 | 3)) {
            return Err(element_error(
                &lines,
                file,
                root,
                format!(
                    "version: expected a Mitsuba 2 or 3 scene (version=\"3.0.0\"), found {version:?}"
                ),
            ));
        }
        // Objects nest: a stack of (XML element whose children remain, object index).
        let mut stack: Vec<(roxmltree::Children, usize)> = vec![(root.children(), parent)];
        while let Some((children, owner)) = stack.last_mut() {
            let owner = *owner;
            let Some(node) = children.next() else {
                stack.pop();
                continue;
            };
            if !node.is_element() {
                continue;
            }
            let tag = node.tag_name().name();
            let err = |m: String| element_error(&lines, file, node, m);
            let at = Loc::line(file, lines.line(node.range().start));
            match tag {
                "default" => {
                    let name = self.attr(node, "name", &lines, file)?;
                    let value = self.attr(node, "value", &lines, file)?;
                    self.params.entry(name).or_insert(value);
                }
                "include" => {
                    if depth + 1 > MAX_INCLUDE_DEPTH {
                        return Err(err(format!(
                            "includes nested more than {MAX_INCLUDE_DEPTH} deep (does a file include itself?)"
                        )));
                    }
                    let name = self.attr(node, "filename", &lines, file)?;
                    let here = self.sources[src].folder.join(&name);
                    let path = if here.exists() {
                        here
                    } else {
                        self.search
                            .iter()
                            .map(|f| f.join(&name))
                            .find(|p| p.exists())
                            .unwrap_or(here)
                    };
                    let inc = self.load(&path, Some((file, at.line)))?;
                    self.walk_file(inc, owner, depth + 1)?;
                }
                "ref" => {
                    let id = self.attr(node, "id", &lines, file)?;
                    let name = node.attribute("name").map(|n| self.substitute(n, &at, tag));
                    let name = name.transpose()?;
                    let slot = self.objects[owner].children.len();
                    match self.ids.get(&id) {
                        Some(&target) => self.objects[owner].children.push((name, target)),
                        None => {
                            self.objects[owner].children.push((name, usize::MAX));
                            self.pending_refs.push((owner, slot, id, at));
                        }
                    }
                }
                t if OBJECT_TAGS.contains(&t) => {
                    if self.objects.len() >= MAX_OBJECTS {
                        return Err(err(format!("more than {MAX_OBJECTS} objects in one scene")));
                    }
                    let kind = self.attr(node, "type", &lines, file)?;
                    let id = node
                        .attribute("id")
                        .map(|v| self.substitute(v, &at, tag))
                        .transpose()?;
                    let name = node
                        .attribute("name")
                        .map(|v| self.substitute(v, &at, tag))
                        .transpose()?;
                    let index = self.objects.len();
                    if let Some(id) = &id {
                        if self.ids.insert(id.clone(), index).is_some() {
                            return Err(err(format!("id {id:?} is given to two objects")));
                        }
                    }
                    self.objects.push(Object {
                        tag: t.to_string(),
                        kind,
                        id,
                        at,
                        props: Vec::new(),
                        children: Vec::new(),
                    });
                    self.objects[owner].children.push((name, index));
                    stack.push((node.children(), index));
                }
                t if PROPERTY_TAGS.contains(&t) => {
                    let name = self.attr(node, "name", &lines, file)?;
                    let value = self.property(node, &lines, file)?;
                    self.objects[owner].props.push(Property { name, value, at });
                }
                "path" => {
                    // A folder that later file names are also looked for in.
                    let value = self.attr(node, "value", &lines, file)?;
                    if self.search.len() >= MAX_SCENE_FILES {
                        return Err(err(format!(
                            "more than {MAX_SCENE_FILES} search folders"
                        )));
                    }
                    let folder = self.sources[src].folder.join(value);
                    self.search.push(folder);
                }
                other => {
                    return Err(err(format!(
                        "unknown element <{other}> (expected an object such as <shape>, a property such as <float>, <ref>, <default> or <include>)"
                    )))
                }
            }
        }
        Ok(())
    }

    /// The attribute `name` of `node`, with `$params` substituted.
    fn attr(
        &self,
        node: XmlNode,
        name: &str,
        lines: &prism_math::LineIndex,
        file: &str,
    ) -> Result<String, SceneError> {
        let at = Loc::line(file, lines.line(node.range().start));
        match node.attribute(name) {
            Some(v) => self.substitute(v, &at, node.tag_name().name()),
            None => Err(element_error(
                lines,
                file,
                node,
                format!("expected a {name} attribute"),
            )),
        }
    }

    /// `text` with each `$name` replaced by its value.
    fn substitute(&self, text: &str, at: &Loc, element: &str) -> Result<String, SceneError> {
        if !text.contains('$') {
            return Ok(text.to_string());
        }
        let mut out = String::with_capacity(text.len());
        let mut rest = text;
        while let Some(i) = rest.find('$') {
            out.push_str(&rest[..i]);
            let after = &rest[i + 1..];
            let len = after
                .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                .unwrap_or(after.len());
            let name = &after[..len];
            match self.params.get(name) {
                Some(v) if !name.is_empty() => out.push_str(v),
                _ => {
                    return Err(SceneError::Element {
                        at: at.clone(),
                        element: element.to_string(),
                        message: format!(
                        "${name}: no value (give -D {name}=VALUE or a <default name=\"{name}\">)"
                    ),
                    })
                }
            }
            rest = &after[len..];
        }
        out.push_str(rest);
        Ok(out)
    }

    /// The value of the property element `node`.
    fn property(
        &self,
        node: XmlNode,
        lines: &prism_math::LineIndex,
        file: &str,
    ) -> Result<Value, SceneError> {
        let tag = node.tag_name().name();
        let err = |m: String| element_error(lines, file, node, m);
        let value = || self.attr(node, "value", lines, file);
        Ok(match tag {
            "integer" => {
                let v = value()?;
                Value::Integer(
                    v.trim()
                        .parse()
                        .map_err(|_| err(format!("value: expected a whole number, found {v:?}")))?,
                )
            }
            "float" => Value::Float(number(&value()?).map_err(err)?),
            "boolean" => {
                let v = value()?;
                match v.trim().to_ascii_lowercase().as_str() {
                    "true" => Value::Boolean(true),
                    "false" => Value::Boolean(false),
                    _ => return Err(err(format!("value: expected true or false, found {v:?}"))),
                }
            }
            "string" => Value::String(value()?),
            "rgb" => Value::Rgb(colour(&value()?).map_err(err)?),
            "spectrum" => {
                let v = value()?;
                if v.contains(':') {
                    return Err(err(
                        "a spectrum of wavelengths: not supported by prism (give an <rgb>)".into(),
                    ));
                }
                Value::Rgb(colour(&v).map_err(err)?)
            }
            "point" | "vector" => {
                let p = match node.attribute("value") {
                    Some(_) => triple(&value()?).map_err(err)?,
                    None => {
                        let mut c = [0.0; 3];
                        for (i, axis) in ["x", "y", "z"].into_iter().enumerate() {
                            if let Some(v) = node.attribute(axis) {
                                let at = Loc::line(file, lines.line(node.range().start));
                                c[i] = number(&self.substitute(v, &at, tag)?).map_err(err)?;
                            }
                        }
                        DVec3::from_array(c)
                    }
                };
                if tag == "point" {
                    Value::Point(p)
                } else {
                    Value::Vector(p)
                }
            }
            "transform" => {
                let at = Loc::line(file, lines.line(node.range().start));
                Value::Transform(read_transform(
                    node,
                    &|v| self.substitute(v, &at, tag),
                    &|n, m| element_error(lines, file, n, m),
                )?)
            }
            _ => unreachable!("only property tags reach here"),
        })
    }

    /// Points every `<ref>` met before its object at the object.
    fn resolve_refs(&mut self) -> Result<(), SceneError> {
        for (owner, slot, id, at) in std::mem::take(&mut self.pending_refs) {
            let Some(&target) = self.ids.get(&id) else {
                return Err(SceneError::Element {
                    at,
                    element: "ref".into(),
                    message: format!("id {id:?}: no object has this id"),
                });
            };
            self.objects[owner].children[slot].1 = target;
        }
        Ok(())
    }
}
