//! Split renders: the part file one share of a render writes (a tiled OpenEXR file holding
//! only the share's 32x32 tiles: the mean radiance, each pixel's sums and sample count, and
//! the render's identity, a [`PartIdentity`], as string attributes), written whole
//! ([`Part`]) or tile by tile as they render ([`PartWriter`]), and [`merge_rows`], which
//! checks that a set of parts makes one whole render and adds them up a row of tiles at a
//! time.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::{Seek, Write};
use std::path::{Path, PathBuf};

use prism_image::{ExrLayers, ExrSamples, Image, ImageError, TiledExrReader, TiledExrWriter};
use prism_math::ExactSum;

use crate::film::{tile_count, tile_of, tiles, PixelSum, Share, TILE};

mod identity;

pub use self::identity::{Encoding, IdentityError, PartIdentity, Renderer};

/// Attribute-name prefix of a part's identity and share.
const PREFIX: &str = "prism.";
/// The share's attributes: `I/N` and `A..B`.
const PART: &str = "prism.part";
const SAMPLES: &str = "prism.samples";
/// Identity keys every part has: what it renders, its size and its samples per pixel.
const REQUIRED: [&str; 4] = ["kind", "width", "height", "spp"];

/// The channels of the exact radiance sums: for R, G and B, four 32-bit words each, least
/// significant first.
fn sum_channels() -> [[String; 4]; 3] {
    ["R", "G", "B"].map(|c| [0, 1, 2, 3].map(|w| format!("sum.{c}.w{w}")))
}

/// What can be wrong with a part file or a set of them.
#[derive(Debug, thiserror::Error)]
pub enum PartError {
    /// The file cannot be read, or is not an OpenEXR file in the subset prism reads.
    #[error(transparent)]
    Image(#[from] ImageError),
    /// The file lacks an attribute or channel every part has.
    #[error("{file}: not a prism part file: it has no {what}")]
    NotAPart {
        /// The file.
        file: PathBuf,
        /// The attribute or channel missing.
        what: String,
    },
    /// An attribute's value is malformed.
    #[error("{file}: attribute {name} is `{value}`; expected {expected}")]
    BadAttribute {
        /// The file.
        file: PathBuf,
        /// The attribute.
        name: String,
        /// Its value.
        value: String,
        /// What was expected.
        expected: &'static str,
    },
    /// A pixel's data contradicts the part's share.
    #[error("{file}: corrupt: pixel ({x}, {y}) {why}")]
    Corrupt {
        /// The file.
        file: PathBuf,
        /// Column.
        x: u32,
        /// Row, 0 at the top.
        y: u32,
        /// What is wrong.
        why: String,
    },
    /// A part belongs to another render than the first part.
    #[error("{file}: {key} is {found}, but {first} has {expected}: the parts are from different renders")]
    Mismatch {
        /// The part that differs.
        file: PathBuf,
        /// The setting.
        key: String,
        /// Its value there.
        found: String,
        /// The first part.
        first: PathBuf,
        /// Its value in the first part.
        expected: String,
    },
    /// Two parts cover the same tiles and samples.
    #[error("{second} repeats {what} of {first}")]
    Doubled {
        /// The part met first.
        first: PathBuf,
        /// The part that covers some of the same work.
        second: PathBuf,
        /// The work both cover.
        what: String,
    },
    /// Some tiles or samples are in no part.
    #[error("missing {}: {}", if .holes.len() == 1 { "part" } else { "parts" }, .holes.join(", "))]
    Missing {
        /// Each missing share, as `tiles I/N, samples A..B`.
        holes: Vec<String>,
    },
    /// No part was given.
    #[error("no part files given")]
    NoParts,
    /// The merged image's sums would be larger than the memory budget.
    #[error("{file}: a {width}x{height} render {source}")]
    OverBudget {
        /// The first part, which gives the size.
        file: PathBuf,
        /// Width in pixels.
        width: u32,
        /// Height in pixels.
        height: u32,
        /// What the sums need and the budget.
        #[source]
        source: prism_math::limits::OverBudget,
    },
}

/// What a part is a share of: the render's identity (every setting that changes pixels, by
/// name) and the share.
#[derive(Clone, Debug, PartialEq)]
pub struct PartHeader {
    /// Settings by name (`kind`, `width`, `height`, `spp`, `scene`, ...), sorted by name.
    pub identity: Vec<(String, String)>,
    /// The tiles and samples this part holds.
    pub share: Share,
}

impl PartHeader {
    /// The identity setting `key`.
    #[must_use]
    pub fn setting(&self, key: &str) -> Option<&str> {
        self.identity
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }

    /// The header as a part file's string attributes: `prism.<key>` for the identity,
    /// `prism.part` (`I/N`) and `prism.samples` (`A..B`).
    fn attributes(&self) -> Vec<(String, String)> {
        let mut attributes: Vec<(String, String)> = self
            .identity
            .iter()
            .map(|(k, v)| (format!("{PREFIX}{k}"), v.clone()))
            .collect();
        attributes.push((
            PART.into(),
            format!("{}/{}", self.share.part, self.share.parts),
        ));
        attributes.push((
            SAMPLES.into(),
            format!("{}..{}", self.share.samples.start, self.share.samples.end),
        ));
        attributes
    }

    /// The header held in an OpenEXR file's attributes (the channels need hold no samples);
    /// `file` names it in errors.
    ///
    /// # Errors
    /// [`PartError::NotAPart`] without the attributes and channels of a part,
    /// [`PartError::BadAttribute`] for a malformed attribute.
    pub fn from_exr(layers: &ExrLayers, file: &Path) -> Result<PartHeader, PartError> {
        let not_a_part = |what: &str| PartError::NotAPart {
            file: file.to_path_buf(),
            what: what.to_string(),
        };
        let bad = |name: &str, value: &str, expected: &'static str| PartError::BadAttribute {
            file: file.to_path_buf(),
            name: name.to_string(),
            value: value.to_string(),
            expected,
        };
        let attribute = |name: &str| {
            layers
                .attribute(name)
                .ok_or_else(|| not_a_part(&format!("attribute {name}")))
        };
        let mut identity: Vec<(String, String)> = layers
            .attributes
            .iter()
            .filter(|(k, _)| k.starts_with(PREFIX) && k != PART && k != SAMPLES)
            .map(|(k, v)| (k[PREFIX.len()..].to_string(), v.clone()))
            .collect();
        identity.sort();
        for k in REQUIRED {
            attribute(&format!("{PREFIX}{k}"))?;
        }
        let number = |key: &str| -> Result<u32, PartError> {
            let name = format!("{PREFIX}{key}");
            let v = attribute(&name)?;
            v.parse().map_err(|_| bad(&name, v, "a whole number"))
        };
        let (width, height, spp) = (number("width")?, number("height")?, number("spp")?);
        if (width, height) != (layers.width, layers.height) {
            return Err(bad(
                "dataWindow",
                &format!("{}x{}", layers.width, layers.height),
                "the size in prism.width and prism.height",
            ));
        }
        let part_text = attribute(PART)?;
        let (part, parts) = part_text
            .split_once('/')
            .and_then(|(a, b)| Some((a.parse::<u32>().ok()?, b.parse::<u32>().ok()?)))
            .filter(|&(i, n)| n >= 1 && i < n)
            .ok_or_else(|| bad(PART, part_text, "I/N with 0 <= I < N"))?;
        if parts as usize > tile_count(width, height) {
            return Err(bad(
                PART,
                part_text,
                "I/N with N at most the image's number of 32x32 tiles",
            ));
        }
        let samples_text = attribute(SAMPLES)?;
        let samples = samples_text
            .split_once("..")
            .and_then(|(a, b)| Some(a.parse::<u32>().ok()?..b.parse::<u32>().ok()?))
            .filter(|r| r.start < r.end && r.end <= spp)
            .ok_or_else(|| bad(SAMPLES, samples_text, "A..B with 0 <= A < B <= prism.spp"))?;
        for name in ["Y.sum", "Y.sumsq"] {
            if !matches!(layers.channel(name), Some(ExrSamples::Float(_))) {
                return Err(not_a_part(&format!("float channel {name}")));
            }
        }
        for name in sum_channels()
            .iter()
            .flatten()
            .map(String::as_str)
            .chain(["samples"])
        {
            if !matches!(layers.channel(name), Some(ExrSamples::Uint(_))) {
                return Err(not_a_part(&format!("uint channel {name}")));
            }
        }
        Ok(PartHeader {
            identity,
            share: Share {
                part,
                parts,
                samples,
            },
        })
    }
}

/// One share of a render: its header and each pixel's sums (pixels outside the share hold
/// none).
#[derive(Clone, Debug, PartialEq)]
pub struct Part {
    /// The render and the share.
    pub header: PartHeader,
    /// Each pixel's sums.
    pub sums: Image<PixelSum>,
}

impl Part {
    /// A part of a render whose settings are `identity`; it must hold `kind`, `width`,
    /// `height` and `spp`.
    ///
    /// # Panics
    /// If a required identity key is missing.
    #[must_use]
    pub fn new(mut identity: Vec<(String, String)>, share: Share, sums: Image<PixelSum>) -> Part {
        identity.sort();
        for k in REQUIRED {
            assert!(
                identity.iter().any(|(n, _)| n == k),
                "a part's identity needs {k}"
            );
        }
        Part {
            header: PartHeader { identity, share },
            sums,
        }
    }

    /// The part as OpenEXR channels and attributes: `R`, `G`, `B` the mean radiance (what
    /// other tools show), `sum.R.w0` to `sum.R.w3` (and for G and B) the exact radiance
    /// sums' 32-bit words, least significant first, `Y.sum` and `Y.sumsq` the luminance
    /// moments (rounded to 32-bit floats), `samples` the sample count;
    /// attributes `prism.<key>` for the identity, `prism.part` (`I/N`) and `prism.samples`
    /// (`A..B`).
    #[must_use]
    pub fn to_exr(&self) -> ExrLayers {
        let mut layers = channels(self.sums.pixels(), self.sums.width(), self.sums.height());
        layers.attributes = self.header.attributes();
        layers
    }

    /// Writes the part atomically as a tiled file of its share's tiles (see
    /// [`PartWriter`]): a re-run part replaces the old file whole or not at all.
    ///
    /// # Errors
    /// [`PartError::Image`] if the file cannot be written.
    pub fn write(&self, path: &Path) -> Result<(), PartError> {
        let (w, h) = (self.sums.width(), self.sums.height());
        let identity = self.header.identity.clone();
        let share = self.header.share.clone();
        Ok(prism_image::write_atomic(path, |out| {
            let mut part = PartWriter::new(out, identity, share, w, h)?;
            for (k, &(x0, y0)) in tiles(w, h).iter().enumerate() {
                if self.header.share.has_tile(k) {
                    let tile: Vec<PixelSum> = tile_pixels((x0, y0), w, h)
                        .map(|(x, y)| self.sums.get(x, y))
                        .collect();
                    part.add((x0, y0), &tile)?;
                }
            }
            part.finish()?;
            Ok(())
        })?)
    }

    /// Reads a part file whole, checking its attributes and that every pixel's data fits
    /// its share (see [`PartFile`]).
    ///
    /// # Errors
    /// As [`PartFile::open`] and [`PartFile::load`].
    pub fn read(path: &Path) -> Result<Part, PartError> {
        PartFile::open(path)?.load()
    }

    /// The part held in OpenEXR channels and attributes; `file` names it in errors.
    ///
    /// # Errors
    /// [`PartError::NotAPart`] without the attributes and channels of a part,
    /// [`PartError::BadAttribute`] for a malformed one, [`PartError::Corrupt`] for a pixel
    /// whose sample count or sums contradict the share.
    pub fn from_exr(layers: &ExrLayers, file: &Path) -> Result<Part, PartError> {
        let header = PartHeader::from_exr(layers, file)?;
        let mut sums = Image::new(layers.width, layers.height, PixelSum::default());
        each_pixel(layers, (0, 0), &header, file, |x, y, s| sums.set(x, y, s))?;
        Ok(Part { header, sums })
    }
}

/// The pixels of the tile at `(x0, y0)` of a `w x h` film, row by row.
fn tile_pixels((x0, y0): (u32, u32), w: u32, h: u32) -> impl Iterator<Item = (u32, u32)> {
    (y0..(y0 + TILE).min(h)).flat_map(move |y| (x0..(x0 + TILE).min(w)).map(move |x| (x, y)))
}

/// A part's channels for `sums`, `w x h` pixels row by row (a tile or the whole image): `R`,
/// `G`, `B` the mean radiance (what other tools show), `sum.R.w0` to `sum.R.w3` (and for G
/// and B) the exact radiance sums' 32-bit words, least significant first, `Y.sum` and
/// `Y.sumsq` the luminance moments (rounded to 32-bit floats), `samples` the sample count.
fn channels(sums: &[PixelSum], w: u32, h: u32) -> ExrLayers {
    let float = |f: &dyn Fn(&PixelSum) -> f32| ExrSamples::Float(sums.iter().map(f).collect());
    let means: Vec<[f32; 3]> = sums.iter().map(|s| s.mean().to_array()).collect();
    let mean = |c: usize| ExrSamples::Float(means.iter().map(|m| m[c]).collect());
    let mut layers = ExrLayers {
        width: w,
        height: h,
        channels: vec![
            ("R".into(), mean(0)),
            ("G".into(), mean(1)),
            ("B".into(), mean(2)),
            ("Y.sum".into(), float(&|s| s.moment1 as f32)),
            ("Y.sumsq".into(), float(&|s| s.moment2 as f32)),
            (
                "samples".into(),
                ExrSamples::Uint(sums.iter().map(|s| s.n).collect()),
            ),
        ],
        attributes: Vec::new(),
    };
    for (c, names) in sum_channels().into_iter().enumerate() {
        for (w, name) in names.into_iter().enumerate() {
            let words = sums.iter().map(|s| s.sum[c].words()[w]).collect();
            layers.channels.push((name, ExrSamples::Uint(words)));
        }
    }
    layers
}

/// Checks every pixel held in `layers` (at `origin` of the image: the whole image or one
/// tile) against `header`'s share, then hands each pixel of the share to `f` as
/// `(x, y, sums)`, row by row. `layers` must hold the channels `header`'s check found.
fn each_pixel(
    layers: &ExrLayers,
    origin: (u32, u32),
    header: &PartHeader,
    file: &Path,
    mut f: impl FnMut(u32, u32, PixelSum),
) -> Result<(), PartError> {
    let float = |name: &str| match layers.channel(name) {
        Some(ExrSamples::Float(v)) => Ok(v),
        _ => Err(PartError::NotAPart {
            file: file.to_path_buf(),
            what: format!("float channel {name}"),
        }),
    };
    let (m1, m2) = (float("Y.sum")?, float("Y.sumsq")?);
    let uint = |name: &str| match layers.channel(name) {
        Some(ExrSamples::Uint(v)) => Ok(v),
        _ => Err(PartError::NotAPart {
            file: file.to_path_buf(),
            what: format!("uint channel {name}"),
        }),
    };
    let n = uint("samples")?;
    let mut words: Vec<&Vec<u32>> = Vec::with_capacity(12);
    for name in sum_channels().iter().flatten() {
        words.push(uint(name)?);
    }
    let (width, height) = (layers.width, layers.height);
    let image_width = header
        .setting("width")
        .and_then(|v| v.parse().ok())
        .unwrap_or(width);
    let share = &header.share;
    let (part, parts) = (share.part, share.parts);
    let most = share.samples.len() as u32;
    for ty in 0..height {
        for tx in 0..width {
            let i = (ty * width + tx) as usize;
            let (x, y) = (origin.0 + tx, origin.1 + ty);
            let word = |c: usize, k: usize| words[4 * c + k][i];
            let s = PixelSum {
                sum: [0, 1, 2].map(|c| {
                    ExactSum::from_words([word(c, 0), word(c, 1), word(c, 2), word(c, 3)])
                }),
                moment1: f64::from(m1[i]),
                moment2: f64::from(m2[i]),
                n: n[i],
                ..PixelSum::default()
            };
            let corrupt = |why: String| PartError::Corrupt {
                file: file.to_path_buf(),
                x,
                y,
                why,
            };
            let mine = share.has_tile(tile_of(x, y, image_width));
            if mine && !(1..=most).contains(&s.n) {
                return Err(corrupt(format!(
                    "holds {} samples; its share takes 1 to {most}",
                    s.n
                )));
            }
            if !mine && s != PixelSum::default() {
                return Err(corrupt(format!(
                    "holds data, but its tile is not in share {part}/{parts}"
                )));
            }
            if !(s.moment1.is_finite() && s.moment2.is_finite()) {
                return Err(corrupt("holds a moment that is not finite".into()));
            }
            if mine {
                f(x, y, s);
            }
        }
    }
    Ok(())
}

/// A part file being written tile by tile: [`PartWriter::add`] takes the share's tiles in
/// any order and writes them in order (so the bytes do not depend on which tile finished
/// first), holding those that arrive early until the ones before them are in.
pub struct PartWriter<W: Write + Seek> {
    exr: TiledExrWriter<W>,
    share: Share,
    size: (u32, u32),
    /// The share's tiles, in order: their row-major index and origin.
    order: Vec<(usize, (u32, u32))>,
    /// How many of `order` are written.
    written: usize,
    /// Tiles that arrived before the ones ahead of them, by row-major index.
    early: BTreeMap<usize, Vec<PixelSum>>,
}

impl<W: Write + Seek> PartWriter<W> {
    /// Starts the part file of `share` of a `width x height` render whose settings are
    /// `identity` (it must hold `kind`, `width`, `height` and `spp`).
    ///
    /// # Errors
    /// [`PartError::Image`] if `out` fails.
    ///
    /// # Panics
    /// If a required identity key is missing.
    pub fn new(
        out: W,
        mut identity: Vec<(String, String)>,
        share: Share,
        width: u32,
        height: u32,
    ) -> Result<Self, ImageError> {
        identity.sort();
        for k in REQUIRED {
            assert!(
                identity.iter().any(|(n, _)| n == k),
                "a part's identity needs {k}"
            );
        }
        let header = PartHeader {
            identity,
            share: share.clone(),
        };
        let mut layers = channels(&[], width, height);
        layers.attributes = header.attributes();
        let exr = TiledExrWriter::new(out, &layers, TILE)?;
        let order = tiles(width, height)
            .into_iter()
            .enumerate()
            .filter(|&(k, _)| share.has_tile(k))
            .collect();
        Ok(PartWriter {
            exr,
            share,
            size: (width, height),
            order,
            written: 0,
            early: BTreeMap::new(),
        })
    }

    /// Takes the tile at `origin`: its pixels' sums row by row.
    ///
    /// # Errors
    /// [`PartError::Image`] if the destination fails.
    ///
    /// # Panics
    /// If the tile is not the share's or has the wrong number of pixels.
    pub fn add(&mut self, origin: (u32, u32), sums: &[PixelSum]) -> Result<(), ImageError> {
        let k = tile_of(origin.0, origin.1, self.size.0);
        assert!(self.share.has_tile(k), "a tile of the share");
        if self.order.get(self.written).map(|&(next, _)| next) != Some(k) {
            // Early: kept until the tiles before it are in.
            self.early.insert(k, sums.to_vec());
            return Ok(());
        }
        self.write_next(sums)?;
        while let Some(&(k, _)) = self.order.get(self.written) {
            let Some(sums) = self.early.remove(&k) else {
                break;
            };
            self.write_next(&sums)?;
        }
        Ok(())
    }

    /// Writes the next tile of the share, in order.
    fn write_next(&mut self, sums: &[PixelSum]) -> Result<(), ImageError> {
        let (_, (x0, y0)) = self.order[self.written];
        let (w, h) = self.size;
        let (tw, th) = ((w - x0).min(TILE), (h - y0).min(TILE));
        assert_eq!(
            sums.len(),
            (tw * th) as usize,
            "one sum a pixel of the tile"
        );
        self.exr
            .write_tile(x0 / TILE, y0 / TILE, &channels(sums, tw, th))?;
        self.written += 1;
        Ok(())
    }

    /// Ends the file, handing back the writer.
    ///
    /// # Errors
    /// [`PartError::Image`] if the destination fails.
    ///
    /// # Panics
    /// If a tile of the share is missing.
    pub fn finish(self) -> Result<W, ImageError> {
        assert_eq!(
            self.written,
            self.order.len(),
            "every tile of the share added"
        );
        self.exr.finish()
    }
}

/// A part file opened for merging: its header and tile table read and checked, its tiles
/// read and decoded only when merged.
pub struct PartFile {
    /// The file.
    pub path: PathBuf,
    /// What it is a share of.
    pub header: PartHeader,
    reader: TiledExrReader<File>,
}

impl std::fmt::Debug for PartFile {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PartFile")
            .field("path", &self.path)
            .field("header", &self.header)
            .finish_non_exhaustive()
    }
}

impl PartFile {
    /// Opens a part file and checks its header and that it holds exactly its share's tiles.
    ///
    /// # Errors
    /// [`PartError::Image`] if it cannot be read or is not a tiled OpenEXR file prism
    /// reads, [`PartError::Corrupt`] if its tiles are not its share's, else as
    /// [`PartHeader::from_exr`].
    pub fn open(path: &Path) -> Result<PartFile, PartError> {
        let reader = TiledExrReader::open(path)?;
        let header = PartHeader::from_exr(&reader.header(), path)?;
        if reader.tile_size() != (TILE, TILE) {
            return Err(PartError::NotAPart {
                file: path.to_path_buf(),
                what: format!("{TILE}x{TILE} tiles"),
            });
        }
        let (across, down) = reader.tiles();
        for ty in 0..down {
            for tx in 0..across {
                let mine = header.share.has_tile((ty * across + tx) as usize);
                if mine != reader.has_tile(tx, ty) {
                    return Err(PartError::Corrupt {
                        file: path.to_path_buf(),
                        x: tx * TILE,
                        y: ty * TILE,
                        why: if mine {
                            format!(
                                "is in a tile of share {} that the file lacks",
                                header.share.part
                            )
                        } else {
                            format!(
                                "is in a tile the file holds outside share {}",
                                header.share.part
                            )
                        },
                    });
                }
            }
        }
        Ok(PartFile {
            path: path.to_path_buf(),
            header,
            reader,
        })
    }

    /// The sums of tile `(tx, ty)` (of the share), checked against the share, each handed
    /// to `f` as `(x, y, sums)`.
    fn tile(
        &mut self,
        tx: u32,
        ty: u32,
        f: impl FnMut(u32, u32, PixelSum),
    ) -> Result<(), PartError> {
        let layers = self
            .reader
            .read_tile(tx, ty)?
            .ok_or_else(|| PartError::Corrupt {
                file: self.path.clone(),
                x: tx * TILE,
                y: ty * TILE,
                why: "is in a tile the file lacks".to_string(),
            })?;
        each_pixel(&layers, (tx * TILE, ty * TILE), &self.header, &self.path, f)
    }

    /// Decodes the part's pixels whole and checks them against its share.
    ///
    /// # Errors
    /// [`PartError::Image`] if a tile does not decode, [`PartError::Corrupt`] for a pixel
    /// whose sample count or sums contradict the share.
    pub fn load(mut self) -> Result<Part, PartError> {
        let (w, h) = merged_size(std::slice::from_ref(&self));
        sums_fit(&self.path, (w, h), u64::from(w) * u64::from(h))?;
        let mut sums = Image::new(w, h, PixelSum::default());
        let (across, down) = self.reader.tiles();
        for ty in 0..down {
            for tx in 0..across {
                if self.header.share.has_tile((ty * across + tx) as usize) {
                    self.tile(tx, ty, |x, y, s| sums.set(x, y, s))?;
                }
            }
        }
        Ok(Part {
            header: self.header,
            sums,
        })
    }
}

/// A merged render.
#[derive(Clone, Debug)]
pub struct Merged {
    /// The identity the parts share.
    pub identity: Vec<(String, String)>,
    /// Each pixel's sums over every part.
    pub sums: Image<PixelSum>,
    /// The shares no part held (only with `allow_missing`), as `tiles I/N, samples A..B`.
    pub holes: Vec<String>,
}

/// The order in which `headers` are added (by share, then first sample), after checking
/// that they are shares of one render and cover every tile and sample at most once; the
/// shares no part holds are listed in the second value.
///
/// # Errors
/// [`PartError::NoParts`] for an empty set, [`PartError::Mismatch`] for parts of
/// different renders or splits, [`PartError::Doubled`] for work held twice.
pub fn merge_order(
    headers: &[(&Path, &PartHeader)],
) -> Result<(Vec<usize>, Vec<String>), PartError> {
    let Some(&(first_file, first)) = headers.first() else {
        return Err(PartError::NoParts);
    };
    for &(file, p) in &headers[1..] {
        let mismatch = |key: &str, found: String, expected: String| PartError::Mismatch {
            file: file.to_path_buf(),
            key: key.to_string(),
            found,
            first: first_file.to_path_buf(),
            expected,
        };
        let keys: std::collections::BTreeSet<&str> = first
            .identity
            .iter()
            .chain(&p.identity)
            .map(|(k, _)| k.as_str())
            .collect();
        // The kind of render first: parts of another renderer differ in many settings, and
        // the kind says why.
        let keys = std::iter::once("kind").chain(keys.into_iter().filter(|&k| k != "kind"));
        for k in keys {
            let (a, b) = (first.setting(k), p.setting(k));
            if a != b {
                let show = |v: Option<&str>| v.map_or("not set".to_string(), |v| v.to_string());
                return Err(mismatch(k, show(b), show(a)));
            }
        }
        if p.share.parts != first.share.parts {
            return Err(mismatch(
                "the tile share count",
                p.share.parts.to_string(),
                first.share.parts.to_string(),
            ));
        }
    }
    let spp: u32 = first
        .setting("spp")
        .and_then(|v| v.parse().ok())
        .unwrap_or(0);
    let count = first.share.parts;
    let mut order: Vec<usize> = (0..headers.len()).collect();
    order.sort_by_key(|&i| (headers[i].1.share.part, headers[i].1.share.samples.start));
    let mut holes = Vec::new();
    let describe = |part: u32, a: u32, b: u32| format!("tiles {part}/{count}, samples {a}..{b}");
    let mut at = 0;
    for share in 0..count {
        let mut next = 0u32;
        let mut last: Option<usize> = None;
        while let Some(&i) = order.get(at).filter(|&&i| headers[i].1.share.part == share) {
            let r = &headers[i].1.share.samples;
            if r.start < next {
                let j = last.expect("an earlier part set `next`");
                return Err(PartError::Doubled {
                    first: headers[j].0.to_path_buf(),
                    second: headers[i].0.to_path_buf(),
                    what: describe(share, r.start, next.min(r.end)),
                });
            }
            if r.start > next {
                holes.push(describe(share, next, r.start));
            }
            next = r.end;
            last = Some(i);
            at += 1;
        }
        if next < spp {
            holes.push(describe(share, next, spp));
        }
    }
    Ok((order, holes))
}

/// Checks that `files` are shares of one render, every tile and sample exactly once, and
/// adds them up a row of tiles at a time, handing each band of rows to `band` as its first
/// row and its pixels' sums row by row (the whole width, up to 32 rows). Each pixel adds its
/// parts in the order of their first sample, whatever the order given, so a tile split gives
/// exactly the sums of the whole render. Only a band's sums and one tile per part at a time
/// are held. With `allow_missing`, missing shares are returned instead of refused (their
/// pixels hold fewer samples, or none).
///
/// # Errors
/// As [`merge_order`], [`PartError::Missing`] for work held nowhere,
/// [`PartError::Corrupt`] for a part whose pixels are corrupt or whose sums overflow, or
/// whatever `band` returns.
pub fn merge_rows<E: From<PartError>>(
    files: &mut [PartFile],
    allow_missing: bool,
    mut band: impl FnMut(u32, &[PixelSum]) -> Result<(), E>,
) -> Result<Vec<String>, E> {
    let headers: Vec<(&Path, &PartHeader)> = files
        .iter()
        .map(|f| (f.path.as_path(), &f.header))
        .collect();
    let (order, holes) = merge_order(&headers)?;
    if !holes.is_empty() && !allow_missing {
        return Err(PartError::Missing { holes }.into());
    }
    let (w, h) = merged_size(files);
    sums_fit(&files[0].path, (w, h), u64::from(w) * u64::from(TILE))?;
    let across = w.div_ceil(TILE);
    let mut sums = Vec::new();
    for ty in 0..h.div_ceil(TILE) {
        let (y0, rows) = (ty * TILE, (h - ty * TILE).min(TILE));
        sums.clear();
        sums.resize((w * rows) as usize, PixelSum::default());
        for &i in &order {
            let file = &mut files[i];
            for tx in 0..across {
                if !file.header.share.has_tile((ty * across + tx) as usize) {
                    continue;
                }
                let mut overflow = None;
                file.tile(tx, ty, |x, y, add| {
                    let acc = &mut sums[((y - y0) * w + x) as usize];
                    if acc.n == 0 {
                        *acc = add;
                    } else if !acc.merge(&add) && overflow.is_none() {
                        overflow = Some((x, y));
                    }
                })?;
                if let Some((x, y)) = overflow {
                    return Err(PartError::Corrupt {
                        file: file.path.clone(),
                        x,
                        y,
                        why: "has sums that overflow when added to the other parts'".to_string(),
                    }
                    .into());
                }
            }
        }
        band(y0, &sums)?;
    }
    Ok(holes)
}

/// Checks that `pixels` pixels' sums fit the memory budget, for a `width x height` render
/// whose part `file` asked for them.
fn sums_fit(file: &Path, (width, height): (u32, u32), pixels: u64) -> Result<(), PartError> {
    let bytes = pixels * size_of::<PixelSum>() as u64;
    prism_math::limits::check_memory(bytes).map_err(|source| PartError::OverBudget {
        file: file.to_path_buf(),
        width,
        height,
        source,
    })
}

/// The size the parts' identity gives (the first part's; [`merge_order`] checks the rest).
#[must_use]
pub fn merged_size(files: &[PartFile]) -> (u32, u32) {
    let setting = |k: &str| {
        files
            .first()
            .and_then(|f| f.header.setting(k))
            .and_then(|v| v.parse::<u32>().ok())
            .unwrap_or(0)
    };
    (setting("width"), setting("height"))
}

/// [`merge_rows`] gathered into one picture of sums.
///
/// # Errors
/// As [`merge_rows`], and [`PartError::OverBudget`] if the picture's sums do not fit the
/// memory budget.
pub fn merge(files: &mut [PartFile], allow_missing: bool) -> Result<Merged, PartError> {
    let (w, h) = merged_size(files);
    if let Some(first) = files.first() {
        sums_fit(&first.path, (w, h), u64::from(w) * u64::from(h))?;
    }
    let mut all = Vec::new();
    let holes = merge_rows(files, allow_missing, |_, rows: &[PixelSum]| {
        all.extend_from_slice(rows);
        Ok::<(), PartError>(())
    })?;
    Ok(Merged {
        identity: files[0].header.identity.clone(),
        sums: Image::from_vec(w, h, all),
        holes,
    })
}
