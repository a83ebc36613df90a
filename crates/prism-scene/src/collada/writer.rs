//! The COLLADA writer: a polygon mesh as a COLLADA 1.4.1 document.

use std::io::Write;

use prism_mesh::PolyMesh;

/// Writes a polygon mesh as a COLLADA 1.4.1 document (`Y_UP`): one geometry with a
/// `<polylist>`, per-vertex normals and texture coordinates when the mesh has them, and one
/// node instancing it. Numbers use the shortest decimal that reads back as the same `f64`.
///
/// # Errors
/// Whatever the writer returns.
pub fn write_collada(mesh: &PolyMesh, out: &mut impl Write) -> std::io::Result<()> {
    let n = mesh.vertex_count();
    let normals = mesh.normals.as_ref().filter(|v| v.len() == n);
    let uvs = mesh.uvs.as_ref().filter(|v| v.len() == n);
    writeln!(out, r#"<?xml version="1.0" encoding="utf-8"?>"#)?;
    writeln!(
        out,
        r#"<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">"#
    )?;
    writeln!(
        out,
        "  <asset><contributor><authoring_tool>prism</authoring_tool></contributor>\
         <unit name=\"meter\" meter=\"1\"/><up_axis>Y_UP</up_axis></asset>"
    )?;
    writeln!(out, "  <library_geometries>")?;
    writeln!(out, r#"    <geometry id="mesh" name="mesh"><mesh>"#)?;
    let source = |out: &mut dyn Write,
                  id: &str,
                  values: &mut dyn Iterator<Item = f64>,
                  count: usize,
                  params: &[&str]|
     -> std::io::Result<()> {
        let stride = params.len();
        write!(
            out,
            r#"      <source id="{id}"><float_array id="{id}-array" count="{}">"#,
            count * stride
        )?;
        let mut buf = ryu::Buffer::new();
        for (i, v) in values.enumerate() {
            if i > 0 {
                out.write_all(b" ")?;
            }
            out.write_all(buf.format(v).as_bytes())?;
        }
        write!(
            out,
            "</float_array><technique_common><accessor source=\"#{id}-array\" count=\"{count}\" stride=\"{stride}\">"
        )?;
        for p in params {
            write!(out, r#"<param name="{p}" type="float"/>"#)?;
        }
        writeln!(out, "</accessor></technique_common></source>")
    };
    source(
        out,
        "mesh-positions",
        &mut mesh.positions.iter().flat_map(|p| [p.x, p.y, p.z]),
        n,
        &["X", "Y", "Z"],
    )?;
    if let Some(ns) = normals {
        source(
            out,
            "mesh-normals",
            &mut ns.iter().flat_map(|p| [p.x, p.y, p.z]),
            n,
            &["X", "Y", "Z"],
        )?;
    }
    if let Some(ts) = uvs {
        source(
            out,
            "mesh-map-0",
            &mut ts.iter().flat_map(|p| [p.x, p.y]),
            n,
            &["S", "T"],
        )?;
    }
    writeln!(
        out,
        r##"      <vertices id="mesh-vertices"><input semantic="POSITION" source="#mesh-positions"/></vertices>"##
    )?;
    writeln!(out, r#"      <polylist count="{}">"#, mesh.face_count())?;
    writeln!(
        out,
        r##"        <input semantic="VERTEX" source="#mesh-vertices" offset="0"/>"##
    )?;
    let mut stride = 1;
    if normals.is_some() {
        writeln!(
            out,
            r##"        <input semantic="NORMAL" source="#mesh-normals" offset="{stride}"/>"##
        )?;
        stride += 1;
    }
    if uvs.is_some() {
        writeln!(
            out,
            r##"        <input semantic="TEXCOORD" source="#mesh-map-0" offset="{stride}" set="0"/>"##
        )?;
        stride += 1;
    }
    write!(out, "        <vcount>")?;
    for (i, f) in mesh.faces().enumerate() {
        if i > 0 {
            write!(out, " ")?;
        }
        write!(out, "{}", f.len())?;
    }
    writeln!(out, "</vcount>")?;
    write!(out, "        <p>")?;
    let mut first = true;
    for f in mesh.faces() {
        for &v in f {
            for _ in 0..stride {
                if !first {
                    write!(out, " ")?;
                }
                first = false;
                write!(out, "{v}")?;
            }
        }
    }
    writeln!(out, "</p>")?;
    writeln!(out, "      </polylist>")?;
    writeln!(out, "    </mesh></geometry>")?;
    writeln!(out, "  </library_geometries>")?;
    writeln!(out, "  <library_visual_scenes><visual_scene id=\"scene\">")?;
    writeln!(
        out,
        r##"    <node id="mesh-node" name="mesh"><instance_geometry url="#mesh"/></node>"##
    )?;
    writeln!(out, "  </visual_scene></library_visual_scenes>")?;
    writeln!(
        out,
        r##"  <scene><instance_visual_scene url="#scene"/></scene>"##
    )?;
    writeln!(out, "</COLLADA>")
}
