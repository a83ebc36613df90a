//! Mitsuba's `.serialized` meshes (format versions 3 and 4): a header, then a zlib stream
//! per mesh holding flags, counts and tight arrays of positions, normals, uvs, colours and
//! triangle indices, with a table of the meshes' offsets at the end of the file.

use prism_math::glam::DVec3;
use prism_math::Vec2;

use super::meshes::ObjectMesh;

/// The magic number every `.serialized` mesh starts with.
const MAGIC: u16 = 0x041C;
/// Largest decompressed mesh read, in bytes.
const MAX_MESH_BYTES: usize = 1 << 30;

/// The flag word's bits.
const HAS_NORMALS: u32 = 0x0001;
const HAS_TEXCOORDS: u32 = 0x0002;
const HAS_COLORS: u32 = 0x0008;
const DOUBLE_PRECISION: u32 = 0x2000;

/// Mesh `index` of the `.serialized` file `bytes`: positions, triangles, normals (if
/// stored) and uvs (if stored; prism's v runs up the image, so `1 - v`). Errors say what is
/// wrong, without the file's name.
pub(super) fn read_serialized(bytes: &[u8], index: u32) -> Result<ObjectMesh, String> {
    let u16_at = |at: usize| -> Option<u16> {
        Some(u16::from_le_bytes(bytes.get(at..at + 2)?.try_into().ok()?))
    };
    let u32_at = |at: usize| -> Option<u32> {
        Some(u32::from_le_bytes(bytes.get(at..at + 4)?.try_into().ok()?))
    };
    let u64_at = |at: usize| -> Option<u64> {
        Some(u64::from_le_bytes(bytes.get(at..at + 8)?.try_into().ok()?))
    };
    let truncated = || "the file ends early".to_string();
    if u16_at(0) != Some(MAGIC) {
        return Err("not a Mitsuba .serialized mesh (no 0x041C at its start)".into());
    }
    let version = u16_at(2).ok_or_else(truncated)?;
    if !matches!(version, 3 | 4) {
        return Err(format!(
            "format version {version}: prism reads versions 3 and 4"
        ));
    }
    let start = if index == 0 {
        0
    } else {
        let n = bytes.len();
        let count = u32_at(n.checked_sub(4).ok_or_else(truncated)?).ok_or_else(truncated)?;
        if index >= count {
            return Err(format!(
                "shape_index {index}: the file holds {count} meshes"
            ));
        }
        let back = u64::from(count - index);
        let offset = if version == 4 {
            let at = (n as u64).checked_sub(8 * back + 4).ok_or_else(truncated)?;
            u64_at(at as usize).ok_or_else(truncated)?
        } else {
            let at = (n as u64)
                .checked_sub(4 * (back + 1))
                .ok_or_else(truncated)?;
            u64::from(u32_at(at as usize).ok_or_else(truncated)?)
        };
        usize::try_from(offset)
            .ok()
            .filter(|&o| o < n)
            .ok_or_else(|| format!("mesh {index}'s offset {offset} lies outside the file"))?
    };
    if u16_at(start) != Some(MAGIC) {
        return Err(format!("mesh {index} does not start with 0x041C"));
    }
    let data = miniz_oxide::inflate::decompress_to_vec_zlib_with_limit(
        bytes.get(start + 4..).ok_or_else(truncated)?,
        MAX_MESH_BYTES,
    )
    .map_err(|e| {
        format!(
            "mesh {index}: its zlib stream does not inflate ({:?})",
            e.status
        )
    })?;
    parse_mesh(&data, version).map_err(|e| format!("mesh {index}: {e}"))
}

/// One inflated mesh record.
fn parse_mesh(data: &[u8], version: u16) -> Result<ObjectMesh, String> {
    let at = std::cell::Cell::new(0usize);
    let take = |n: usize| -> Result<&[u8], String> {
        let from = at.get();
        let s = data
            .get(from..from.checked_add(n).ok_or("counts overflow")?)
            .ok_or("its data ends early")?;
        at.set(from + n);
        Ok(s)
    };
    let flags = u32::from_le_bytes(take(4)?.try_into().expect("4 bytes"));
    if version == 4 {
        // The shape's name, null-terminated.
        while take(1)?[0] != 0 {}
    }
    let vertices = u64::from_le_bytes(take(8)?.try_into().expect("8 bytes"));
    let faces = u64::from_le_bytes(take(8)?.try_into().expect("8 bytes"));
    let size: u64 = if flags & DOUBLE_PRECISION != 0 { 8 } else { 4 };
    let per_vertex = 3
        + if flags & HAS_NORMALS != 0 { 3 } else { 0 }
        + if flags & HAS_TEXCOORDS != 0 { 2 } else { 0 }
        + if flags & HAS_COLORS != 0 { 3 } else { 0 };
    // Everything the counts ask for must be in the record before anything is allocated.
    let need = vertices
        .checked_mul(per_vertex * size)
        .and_then(|v| faces.checked_mul(12).and_then(|f| v.checked_add(f)));
    let remaining = (data.len() - at.get()) as u64;
    if need.is_none_or(|n| n > remaining) || vertices > u64::from(u32::MAX) {
        return Err(format!(
            "{vertices} vertices and {faces} triangles do not fit in its {remaining} bytes"
        ));
    }
    let (nv, nf) = (vertices as usize, faces as usize);
    let floats = |count: usize| -> Result<Vec<f64>, String> {
        let raw = take(count * size as usize)?;
        Ok(if size == 8u64 {
            raw.chunks_exact(8)
                .map(|c| f64::from_le_bytes(c.try_into().expect("8 bytes")))
                .collect()
        } else {
            raw.chunks_exact(4)
                .map(|c| f64::from(f32::from_le_bytes(c.try_into().expect("4 bytes"))))
                .collect()
        })
    };
    let positions: Vec<DVec3> = floats(3 * nv)?
        .chunks_exact(3)
        .map(|c| DVec3::new(c[0], c[1], c[2]))
        .collect();
    let normals = if flags & HAS_NORMALS != 0 {
        Some(
            floats(3 * nv)?
                .chunks_exact(3)
                .map(|c| DVec3::new(c[0], c[1], c[2]))
                .collect(),
        )
    } else {
        None
    };
    let uvs = if flags & HAS_TEXCOORDS != 0 {
        Some(
            floats(2 * nv)?
                .chunks_exact(2)
                .map(|c| Vec2::new(c[0] as f32, 1.0 - c[1] as f32))
                .collect(),
        )
    } else {
        None
    };
    if flags & HAS_COLORS != 0 {
        floats(3 * nv)?;
    }
    let raw = take(12 * nf)?;
    let mut triangles = Vec::with_capacity(nf);
    for c in raw.chunks_exact(12) {
        let t = [0, 4, 8].map(|o| u32::from_le_bytes(c[o..o + 4].try_into().expect("4 bytes")));
        if t.iter().any(|&i| i as usize >= nv) {
            return Err(format!("a triangle names vertex {:?} of {nv}", t));
        }
        triangles.push(t);
    }
    Ok((positions, triangles, normals, uvs))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A version 4 file of two meshes written here by hand (Mitsuba's layout): each reads
    /// back by its index, uvs turned to prism's v, and damaged files are refused.
    #[test]
    fn meshes_read_back_by_index() {
        let mesh = |shift: f32, uv: bool| -> Vec<u8> {
            let mut record = Vec::new();
            let flags = if uv { HAS_TEXCOORDS } else { 0 };
            record.extend(flags.to_le_bytes());
            record.extend(b"tri\0");
            record.extend(3u64.to_le_bytes());
            record.extend(1u64.to_le_bytes());
            for p in [[0.0, 0.0, shift], [1.0, 0.0, shift], [0.0, 1.0, shift]] {
                for x in p {
                    record.extend(x.to_le_bytes());
                }
            }
            if uv {
                for x in [0.0f32, 0.25, 1.0, 0.25, 0.0, 1.0] {
                    record.extend(x.to_le_bytes());
                }
            }
            for i in [0u32, 1, 2] {
                record.extend(i.to_le_bytes());
            }
            let mut out = Vec::new();
            out.extend(MAGIC.to_le_bytes());
            out.extend(4u16.to_le_bytes());
            out.extend(miniz_oxide::deflate::compress_to_vec_zlib(&record, 6));
            out
        };
        let first = mesh(0.0, true);
        let second = mesh(5.0, false);
        let mut file = first.clone();
        file.extend(&second);
        file.extend(0u64.to_le_bytes());
        file.extend((first.len() as u64).to_le_bytes());
        file.extend(2u32.to_le_bytes());
        let (p, t, n, uv) = read_serialized(&file, 0).unwrap();
        assert_eq!((p.len(), t, n), (3, vec![[0, 1, 2]], None));
        assert_eq!(uv.unwrap()[0], Vec2::new(0.0, 0.75));
        let (p, _, _, uv) = read_serialized(&file, 1).unwrap();
        assert_eq!((p[0].z, uv), (5.0, None));
        assert!(read_serialized(&file, 2).unwrap_err().contains("holds 2"));
        assert!(read_serialized(&file[..40], 0).is_err());
        assert!(read_serialized(b"PK\x03\x04", 0)
            .unwrap_err()
            .contains("0x041C"));
    }
}
