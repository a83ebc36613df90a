//! Tiled OpenEXR: [`TiledExrWriter`] writes one level of square tiles, ZIP-compressed, any
//! of which may be left out (an incomplete file, as OpenEXR calls it: its offset is 0), and
//! [`TiledExrReader`] reads such a file a tile at a time, holding only its header and
//! offset table.

use std::fs::File;
use std::io::{Read, Seek, SeekFrom, Write};
use std::path::Path;

use crate::exr::{parse_header, unzip, Header};
use crate::exr_write::{header_bytes, zip, ZIP};
use crate::io::decode_err;
use crate::{ExrLayers, ExrSamples, ImageError};

/// The most bytes a tiled file's header may take.
const MAX_HEADER_BYTES: u64 = 1 << 20;

/// The number of tiles across and down a `width x height` image of `tile`-pixel tiles.
fn tile_grid((w, h): (u64, u64), tile: u32) -> (u64, u64) {
    (w.div_ceil(u64::from(tile)), h.div_ceil(u64::from(tile)))
}

/// A tiled OpenEXR file being written: its header and a zeroed offset table first, then the
/// tiles in the order given, then (by [`TiledExrWriter::finish`]) the table filled in.
pub struct TiledExrWriter<W: Write + Seek> {
    out: W,
    /// The channels' names and types, in name order.
    channels: Vec<(String, i32)>,
    size: (u64, u64),
    tile: u32,
    table_at: u64,
    at: u64,
    offsets: Vec<u64>,
}

impl<W: Write + Seek> TiledExrWriter<W> {
    /// Starts a file the size of `header` with its channels (their types from the empty
    /// sample lists) and string attributes, cut into `tile x tile` tiles.
    ///
    /// # Errors
    /// [`ImageError::Encode`] if `out` fails.
    pub fn new(mut out: W, header: &ExrLayers, tile: u32) -> Result<Self, ImageError> {
        let mut channels: Vec<(String, i32)> = header
            .channels
            .iter()
            .map(|(n, c)| (n.clone(), c.pixel_type()))
            .collect();
        channels.sort();
        let names: Vec<(&str, i32)> = channels.iter().map(|(n, t)| (n.as_str(), *t)).collect();
        let size = (u64::from(header.width), u64::from(header.height));
        let head = header_bytes(
            (size.0 as usize, size.1 as usize),
            &names,
            ZIP,
            Some(tile),
            &header.attributes,
        );
        let (across, down) = tile_grid(size, tile);
        let count = (across * down) as usize;
        out.write_all(&head).map_err(io)?;
        let table_at = head.len() as u64;
        out.write_all(&vec![0u8; 8 * count]).map_err(io)?;
        Ok(TiledExrWriter {
            out,
            channels,
            size,
            tile,
            table_at,
            at: table_at + 8 * count as u64,
            offsets: vec![0; count],
        })
    }

    /// Writes tile `(tx, ty)`: `pixels` holds its channels by name, row by row over the
    /// tile's own width and height (smaller at the right and bottom edges).
    ///
    /// # Errors
    /// [`ImageError::Encode`] if `out` fails.
    ///
    /// # Panics
    /// If the tile is outside the image, was written already, or its channels are not the
    /// file's with a sample a pixel.
    pub fn write_tile(&mut self, tx: u32, ty: u32, pixels: &ExrLayers) -> Result<(), ImageError> {
        let (across, down) = tile_grid(self.size, self.tile);
        assert!(
            u64::from(tx) < across && u64::from(ty) < down,
            "a tile of the image"
        );
        let index = (u64::from(ty) * across + u64::from(tx)) as usize;
        assert_eq!(self.offsets[index], 0, "each tile written once");
        let t = u64::from(self.tile);
        let w = (self.size.0 - u64::from(tx) * t).min(t) as usize;
        let h = (self.size.1 - u64::from(ty) * t).min(t) as usize;
        assert_eq!((pixels.width as usize, pixels.height as usize), (w, h));
        let planes: Vec<&ExrSamples> = self
            .channels
            .iter()
            .map(|(name, ty)| {
                let c = pixels.channel(name).expect("the tile has every channel");
                assert!(c.pixel_type() == *ty && c.len() == w * h, "channel {name}");
                c
            })
            .collect();
        let mut raw = Vec::with_capacity(4 * planes.len() * w * h);
        for y in 0..h {
            for c in &planes {
                let row = y * w..(y + 1) * w;
                match c {
                    ExrSamples::Float(v) => raw.extend(v[row].iter().flat_map(|s| s.to_le_bytes())),
                    ExrSamples::Uint(v) => raw.extend(v[row].iter().flat_map(|s| s.to_le_bytes())),
                }
            }
        }
        let z = zip(&raw);
        let data = if z.len() < raw.len() { z } else { raw };
        let mut chunk = Vec::with_capacity(20 + data.len());
        for v in [tx as i32, ty as i32, 0, 0, data.len() as i32] {
            chunk.extend_from_slice(&v.to_le_bytes());
        }
        chunk.extend_from_slice(&data);
        self.out.write_all(&chunk).map_err(io)?;
        self.offsets[index] = self.at;
        self.at += chunk.len() as u64;
        Ok(())
    }

    /// Fills in the offset table (0 for each tile left out) and hands back the writer,
    /// positioned at the file's end.
    ///
    /// # Errors
    /// [`ImageError::Encode`] if `out` fails.
    pub fn finish(mut self) -> Result<W, ImageError> {
        let table: Vec<u8> = self.offsets.iter().flat_map(|o| o.to_le_bytes()).collect();
        self.out.seek(SeekFrom::Start(self.table_at)).map_err(io)?;
        self.out.write_all(&table).map_err(io)?;
        self.out.seek(SeekFrom::Start(self.at)).map_err(io)?;
        Ok(self.out)
    }
}

/// A failure of the writer's destination.
fn io(e: std::io::Error) -> ImageError {
    ImageError::Encode {
        format: "OpenEXR",
        message: e.to_string(),
    }
}

/// A tiled OpenEXR file open for reading tile by tile: its header and offset table read and
/// checked, its tiles read and decoded only when asked for.
pub struct TiledExrReader<R: Read + Seek> {
    src: R,
    len: u64,
    what: String,
    header: Header,
    offsets: Vec<u64>,
}

impl TiledExrReader<File> {
    /// Opens a tiled file (a regular file only).
    ///
    /// # Errors
    /// [`ImageError::Io`] if it cannot be opened, else as [`TiledExrReader::new`].
    pub fn open(path: &Path) -> Result<Self, ImageError> {
        let io_err = |source| ImageError::Io {
            path: path.to_path_buf(),
            source,
        };
        let file = prism_math::limits::open_input(path).map_err(io_err)?;
        let len = file.metadata().map_err(io_err)?.len();
        TiledExrReader::new(file, len, &path.display().to_string())
    }
}

impl<R: Read + Seek> TiledExrReader<R> {
    /// Reads the header and offset table of the `len`-byte tiled file in `src`; `what` names
    /// it in errors.
    ///
    /// # Errors
    /// [`ImageError::Decode`] for a file that is not a single-part, one-level tiled file
    /// with uncompressed or ZIP tiles, a header over 1 MiB, or an offset table longer than
    /// the file.
    pub fn new(mut src: R, len: u64, what: &str) -> Result<Self, ImageError> {
        let read_err = |e: std::io::Error| decode_err(what, e);
        let mut head = vec![0u8; len.min(MAX_HEADER_BYTES) as usize];
        src.read_exact(&mut head).map_err(read_err)?;
        let header = parse_header(&head, what, true).map_err(|e| {
            if len > MAX_HEADER_BYTES {
                decode_err(what, "the header is over 1 MiB")
            } else {
                e
            }
        })?;
        if !matches!(header.compression, 0 | ZIP) {
            return Err(decode_err(
                what,
                "expected uncompressed or ZIP tiles in a tiled file",
            ));
        }
        if header.channels.iter().any(|(_, t)| !matches!(t, 0 | 2)) {
            return Err(decode_err(
                what,
                "expected 32-bit float or uint channels in a tiled file",
            ));
        }
        let tile = header.tile.expect("a tiled header has tiles");
        let (across, down) = (
            header.size.0.div_ceil(u64::from(tile.0)),
            header.size.1.div_ceil(u64::from(tile.1)),
        );
        let count = across.saturating_mul(down);
        // Each offset takes 8 bytes of the file: a short file cannot ask for a long table.
        if count.saturating_mul(8) > len.saturating_sub(header.end as u64) {
            return Err(decode_err(what, "the file ends before its offset table"));
        }
        src.seek(SeekFrom::Start(header.end as u64))
            .map_err(read_err)?;
        let mut table = vec![0u8; 8 * count as usize];
        src.read_exact(&mut table).map_err(read_err)?;
        let offsets = table
            .chunks_exact(8)
            .map(|b| u64::from_le_bytes(b.try_into().expect("8 bytes")))
            .collect();
        Ok(TiledExrReader {
            src,
            len,
            what: what.to_string(),
            header,
            offsets,
        })
    }

    /// The file's size, channels (each holding no samples) and string attributes.
    #[must_use]
    pub fn header(&self) -> ExrLayers {
        ExrLayers {
            width: self.header.size.0 as u32,
            height: self.header.size.1 as u32,
            channels: self
                .header
                .channels
                .iter()
                .map(|(n, t)| {
                    let empty = match t {
                        0 => ExrSamples::Uint(Vec::new()),
                        _ => ExrSamples::Float(Vec::new()),
                    };
                    (n.clone(), empty)
                })
                .collect(),
            attributes: self.header.attributes.clone(),
        }
    }

    /// The tiles' width and height.
    #[must_use]
    pub fn tile_size(&self) -> (u32, u32) {
        self.header.tile.expect("a tiled header has tiles")
    }

    /// Tiles across and down.
    #[must_use]
    pub fn tiles(&self) -> (u32, u32) {
        let (tw, th) = self.tile_size();
        let (w, h) = self.header.size;
        (
            w.div_ceil(u64::from(tw)) as u32,
            h.div_ceil(u64::from(th)) as u32,
        )
    }

    /// Whether the file holds tile `(tx, ty)`.
    #[must_use]
    pub fn has_tile(&self, tx: u32, ty: u32) -> bool {
        let (across, _) = self.tiles();
        self.offsets
            .get((ty * across + tx) as usize)
            .is_some_and(|&o| o != 0)
    }

    /// Tile `(tx, ty)`'s channels over its own width and height, or `None` if the file does
    /// not hold it.
    ///
    /// # Errors
    /// [`ImageError::Decode`] for a tile whose block is not where the table says, names
    /// another tile, or does not decode to the tile's pixels; [`ImageError::OverBudget`]
    /// for a tile (its channels counted) over one image's memory budget.
    pub fn read_tile(&mut self, tx: u32, ty: u32) -> Result<Option<ExrLayers>, ImageError> {
        let (across, down) = self.tiles();
        if tx >= across || ty >= down {
            return Ok(None);
        }
        let offset = self.offsets[(ty * across + tx) as usize];
        if offset == 0 {
            return Ok(None);
        }
        let what = self.what.as_str();
        let (tw, th) = self.tile_size();
        let (w, h) = self.header.size;
        let w = (w - u64::from(tx) * u64::from(tw)).min(u64::from(tw)) as usize;
        let h = (h - u64::from(ty) * u64::from(th)).min(u64::from(th)) as usize;
        let line_bytes = 4 * self.header.channels.len() * w;
        let expected = line_bytes * h;
        // The raw tile and its channels, each counted against one image's budget before
        // either is allocated (a tile may be as large as its header says).
        prism_math::limits::check_image_memory(2 * expected as u64).map_err(|source| {
            ImageError::OverBudget {
                what: what.to_string(),
                width: w as u64,
                height: h as u64,
                source,
            }
        })?;
        let mut head = [0u8; 20];
        if offset.saturating_add(20) > self.len {
            return Err(decode_err(
                what,
                format!("tile ({tx}, {ty}) lies past the file's end"),
            ));
        }
        let read_err = |e: std::io::Error| decode_err(what, e);
        self.src.seek(SeekFrom::Start(offset)).map_err(read_err)?;
        self.src.read_exact(&mut head).map_err(read_err)?;
        let field = |i: usize| i32::from_le_bytes(head[4 * i..4 * i + 4].try_into().expect("4"));
        if (field(0), field(1), field(2), field(3)) != (tx as i32, ty as i32, 0, 0) {
            return Err(decode_err(
                what,
                format!("the block at tile ({tx}, {ty})'s offset names another tile"),
            ));
        }
        let size = usize::try_from(field(4))
            .ok()
            .filter(|&s| s <= expected && (offset + 20).saturating_add(s as u64) <= self.len)
            .ok_or_else(|| decode_err(what, format!("tile ({tx}, {ty}) has a bad size")))?;
        let mut stored = vec![0u8; size];
        self.src.read_exact(&mut stored).map_err(read_err)?;
        let raw = if size == expected {
            stored
        } else if self.header.compression == ZIP {
            unzip(&stored, expected, what)?
        } else {
            return Err(decode_err(what, "an uncompressed tile has the wrong size"));
        };
        let mut planes: Vec<ExrSamples> = self
            .header
            .channels
            .iter()
            .map(|(_, t)| match t {
                0 => ExrSamples::Uint(Vec::with_capacity(w * h)),
                _ => ExrSamples::Float(Vec::with_capacity(w * h)),
            })
            .collect();
        for line in raw.chunks_exact(line_bytes) {
            for (c, plane) in planes.iter_mut().enumerate() {
                let words = line[4 * w * c..4 * w * (c + 1)]
                    .chunks_exact(4)
                    .map(|b| u32::from_le_bytes(b.try_into().expect("4 bytes")));
                match plane {
                    ExrSamples::Uint(v) => v.extend(words),
                    ExrSamples::Float(v) => v.extend(words.map(f32::from_bits)),
                }
            }
        }
        Ok(Some(ExrLayers {
            width: w as u32,
            height: h as u32,
            channels: self
                .header
                .channels
                .iter()
                .map(|(n, _)| n.clone())
                .zip(planes)
                .collect(),
            attributes: Vec::new(),
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Cursor;

    fn layers(w: u32, h: u32, seed: u32) -> ExrLayers {
        let n = (w * h) as usize;
        ExrLayers {
            width: w,
            height: h,
            channels: vec![
                (
                    "b".into(),
                    ExrSamples::Uint((0..n as u32).map(|i| i * 7 + seed).collect()),
                ),
                (
                    "a".into(),
                    ExrSamples::Float((0..n).map(|i| i as f32 * 0.5 - seed as f32).collect()),
                ),
            ],
            attributes: vec![("note".into(), "x".into())],
        }
    }

    /// Round trip: every tile written comes back as written, the ones left out as `None`,
    /// on an image whose edge tiles are narrower and shorter.
    #[test]
    fn tiles_round_trip_and_absent_tiles_read_as_none() {
        let (w, h, t) = (70u32, 45u32, 32u32);
        let header = ExrLayers {
            channels: layers(1, 1, 0)
                .channels
                .into_iter()
                .map(|(n, c)| match c {
                    ExrSamples::Uint(_) => (n, ExrSamples::Uint(Vec::new())),
                    ExrSamples::Float(_) => (n, ExrSamples::Float(Vec::new())),
                })
                .collect(),
            ..layers(w, h, 0)
        };
        let mut wr = TiledExrWriter::new(Cursor::new(Vec::new()), &header, t).unwrap();
        let size = |tx: u32, ty: u32| ((w - tx * t).min(t), (h - ty * t).min(t));
        let written = [(2, 1), (0, 0), (1, 1)];
        for (k, &(tx, ty)) in written.iter().enumerate() {
            let (tw, th) = size(tx, ty);
            wr.write_tile(tx, ty, &layers(tw, th, k as u32)).unwrap();
        }
        let bytes = wr.finish().unwrap().into_inner();
        let len = bytes.len() as u64;
        let mut r = TiledExrReader::new(Cursor::new(bytes), len, "t.exr").unwrap();
        assert_eq!(r.tiles(), (3, 2));
        assert_eq!(
            r.header().attributes,
            vec![("note".to_string(), "x".to_string())]
        );
        for ty in 0..2 {
            for tx in 0..3 {
                let got = r.read_tile(tx, ty).unwrap();
                match written.iter().position(|&p| p == (tx, ty)) {
                    Some(k) => {
                        let (tw, th) = size(tx, ty);
                        let mut want = layers(tw, th, k as u32);
                        want.channels.sort_by(|a, b| a.0.cmp(&b.0));
                        want.attributes.clear();
                        assert_eq!(got, Some(want));
                    }
                    None => assert_eq!(got, None),
                }
            }
        }
    }

    /// Hostile input: a table that points one tile's block at another's is refused, and a
    /// scanline file is not read as a tiled one.
    #[test]
    fn misplaced_blocks_and_scanline_files_are_refused() {
        let header = layers(40, 10, 0);
        let mut wr = TiledExrWriter::new(Cursor::new(Vec::new()), &header, 32).unwrap();
        let (a, b) = (layers(32, 10, 1), layers(8, 10, 2));
        wr.write_tile(0, 0, &a).unwrap();
        wr.write_tile(1, 0, &b).unwrap();
        let mut bytes = wr.finish().unwrap().into_inner();
        let end = parse_header(&bytes, "t", true).unwrap().end;
        let first: [u8; 8] = bytes[end..end + 8].try_into().unwrap();
        bytes[end + 8..end + 16].copy_from_slice(&first);
        let len = bytes.len() as u64;
        let mut r = TiledExrReader::new(Cursor::new(bytes), len, "t.exr").unwrap();
        assert!(r.read_tile(0, 0).unwrap().is_some());
        let e = r.read_tile(1, 0).unwrap_err().to_string();
        assert!(e.contains("names another tile"), "{e}");
        let scan = crate::encode_exr_layers(&layers(4, 4, 0));
        let len = scan.len() as u64;
        assert!(TiledExrReader::new(Cursor::new(scan), len, "s.exr").is_err());
    }

    /// Hostile input: a header that makes its one tile 65536 x 65536 pixels is refused by
    /// the image budget when the tile is read, before anything of that size is allocated.
    #[test]
    fn a_tile_over_the_budget_is_refused_before_it_is_read() {
        let one = ExrLayers {
            width: 32,
            height: 32,
            channels: vec![("a".into(), ExrSamples::Float(vec![0.5; 32 * 32]))],
            attributes: Vec::new(),
        };
        let mut wr = TiledExrWriter::new(Cursor::new(Vec::new()), &one, 32).unwrap();
        wr.write_tile(0, 0, &one).unwrap();
        let mut bytes = wr.finish().unwrap().into_inner();
        let patch = |bytes: &mut Vec<u8>, name: &[u8], skip: usize, values: &[u32]| {
            let at = bytes.windows(name.len()).position(|w| w == name).unwrap() + skip;
            for (k, v) in values.iter().enumerate() {
                bytes[at + 4 * k..at + 4 * k + 4].copy_from_slice(&v.to_le_bytes());
            }
        };
        // Name, NUL, type name, NUL, size: then the value.
        patch(
            &mut bytes,
            b"dataWindow\0box2i\0",
            21,
            &[0, 0, 65535, 65535],
        );
        patch(&mut bytes, b"tiles\0tiledesc\0", 19, &[65536, 65536]);
        let len = bytes.len() as u64;
        let mut r = TiledExrReader::new(Cursor::new(bytes), len, "big.exr").unwrap();
        assert_eq!(r.tiles(), (1, 1));
        let e = r.read_tile(0, 0).unwrap_err().to_string();
        assert!(e.contains("big.exr: a 65536x65536 image needs"), "{e}");
    }
}
