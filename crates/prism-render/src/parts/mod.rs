//! Split renders: the [`Part`] file one share of a render writes (an OpenEXR file with the
//! mean radiance, each pixel's sums and sample count, and the render's identity, a [`PartIdentity`],
//! as string attributes), and [`merge`], which checks that a set of parts makes one whole render and
//! adds them up.

use std::path::{Path, PathBuf};

use prism_image::{ExrLayers, ExrSamples, Image, ImageError};
use prism_math::ExactSum;

use crate::film::{tile_count, tile_of, PixelSum, Share};

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
        let p = self.sums.pixels();
        let float = |f: &dyn Fn(&PixelSum) -> f32| ExrSamples::Float(p.iter().map(f).collect());
        let means: Vec<[f32; 3]> = p.iter().map(|s| s.mean().to_array()).collect();
        let mean = |c: usize| ExrSamples::Float(means.iter().map(|m| m[c]).collect());
        let h = &self.header;
        let mut attributes: Vec<(String, String)> = h
            .identity
            .iter()
            .map(|(k, v)| (format!("{PREFIX}{k}"), v.clone()))
            .collect();
        attributes.push((PART.into(), format!("{}/{}", h.share.part, h.share.parts)));
        attributes.push((
            SAMPLES.into(),
            format!("{}..{}", h.share.samples.start, h.share.samples.end),
        ));
        let mut layers = ExrLayers {
            width: self.sums.width(),
            height: self.sums.height(),
            channels: vec![
                ("R".into(), mean(0)),
                ("G".into(), mean(1)),
                ("B".into(), mean(2)),
                ("Y.sum".into(), float(&|s| s.moment1 as f32)),
                ("Y.sumsq".into(), float(&|s| s.moment2 as f32)),
                (
                    "samples".into(),
                    ExrSamples::Uint(p.iter().map(|s| s.n).collect()),
                ),
            ],
            attributes,
        };
        for (c, names) in sum_channels().into_iter().enumerate() {
            for (w, name) in names.into_iter().enumerate() {
                let words = p.iter().map(|s| s.sum[c].words()[w]).collect();
                layers.channels.push((name, ExrSamples::Uint(words)));
            }
        }
        layers
    }

    /// Writes the part (see [`Part::to_exr`]) atomically: a re-run part replaces the old
    /// file whole or not at all.
    ///
    /// # Errors
    /// [`PartError::Image`] if the file cannot be written.
    pub fn write(&self, path: &Path) -> Result<(), PartError> {
        Ok(prism_image::write_exr_layers(path, &self.to_exr())?)
    }

    /// Reads a part file, checking its attributes and that every pixel's data fits its share
    /// (see [`Part::from_exr`]).
    ///
    /// # Errors
    /// [`PartError::Image`] if it cannot be read or decoded, else as [`Part::from_exr`].
    pub fn read(path: &Path) -> Result<Part, PartError> {
        Part::from_exr(&prism_image::read_exr_layers(path)?, path)
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
        each_pixel(layers, &header, file, |x, y, s| sums.set(x, y, s))?;
        Ok(Part { header, sums })
    }
}

/// Checks every pixel held in `layers` against `header`'s share, then hands each pixel of the
/// share to `f` as `(x, y, sums)`, row by row. `header` must be the one read from `layers`.
fn each_pixel(
    layers: &ExrLayers,
    header: &PartHeader,
    file: &Path,
    mut f: impl FnMut(u32, u32, PixelSum),
) -> Result<(), PartError> {
    let float = |name: &str| match layers.channel(name) {
        Some(ExrSamples::Float(v)) => v,
        _ => unreachable!("the header check found float channel {name}"),
    };
    let (m1, m2) = (float("Y.sum"), float("Y.sumsq"));
    let uint = |name: &str| match layers.channel(name) {
        Some(ExrSamples::Uint(v)) => v,
        _ => unreachable!("the header check found uint channel {name}"),
    };
    let n = uint("samples");
    let words = sum_channels().map(|names| names.map(|name| uint(&name)));
    let (width, height) = (layers.width, layers.height);
    let share = &header.share;
    let (part, parts) = (share.part, share.parts);
    let most = share.samples.len() as u32;
    for y in 0..height {
        for x in 0..width {
            let i = (y * width + x) as usize;
            let s = PixelSum {
                sum: words.map(|w| ExactSum::from_words([w[0][i], w[1][i], w[2][i], w[3][i]])),
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
            let mine = share.has_tile(tile_of(x, y, width));
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

/// A part file opened for merging: its header read and checked, its pixels decoded only
/// when merged, one part at a time.
#[derive(Clone, Debug)]
pub struct PartFile {
    /// The file.
    pub path: PathBuf,
    /// What it is a share of.
    pub header: PartHeader,
    bytes: Vec<u8>,
}

impl PartFile {
    /// Reads a part file and checks its header.
    ///
    /// # Errors
    /// [`PartError::Image`] if it cannot be read or is not an OpenEXR file prism reads, else
    /// as [`PartHeader::from_exr`].
    pub fn open(path: &Path) -> Result<PartFile, PartError> {
        let limit = prism_image::MAX_IMAGE_FILE_BYTES;
        let bytes =
            prism_math::limits::read_input(path, limit).map_err(|source| ImageError::Io {
                path: path.to_path_buf(),
                source,
            })?;
        let layers = prism_image::decode_exr_header(&bytes, &path.display().to_string())?;
        Ok(PartFile {
            path: path.to_path_buf(),
            header: PartHeader::from_exr(&layers, path)?,
            bytes,
        })
    }

    /// Decodes the part's pixels and checks them against its share.
    ///
    /// # Errors
    /// As [`Part::from_exr`], or [`PartError::Image`] if the pixels do not decode.
    pub fn load(&self) -> Result<Part, PartError> {
        Part::from_exr(&self.layers()?, &self.path)
    }

    /// The decoded channels.
    fn layers(&self) -> Result<ExrLayers, PartError> {
        let what = self.path.display().to_string();
        Ok(prism_image::decode_exr_layers(&self.bytes, &what)?)
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
/// adds them up, decoding one part at a time. Each pixel adds its parts in the order of
/// their first sample, whatever the order given, so a tile split gives exactly the sums of
/// the whole render. With `allow_missing`, missing shares are listed in [`Merged::holes`]
/// instead of refused.
///
/// # Errors
/// As [`merge_order`], [`PartError::Missing`] for work held nowhere, and as
/// [`PartFile::load`] for a part whose pixels are corrupt.
pub fn merge(files: &[PartFile], allow_missing: bool) -> Result<Merged, PartError> {
    let headers: Vec<(&Path, &PartHeader)> = files
        .iter()
        .map(|f| (f.path.as_path(), &f.header))
        .collect();
    let (order, holes) = merge_order(&headers)?;
    if !holes.is_empty() && !allow_missing {
        return Err(PartError::Missing { holes });
    }
    let first = &files[0].header;
    let setting = |k: &str| first.setting(k).and_then(|v| v.parse::<u32>().ok());
    let (w, h) = (
        setting("width").unwrap_or(0),
        setting("height").unwrap_or(0),
    );
    let bytes = u64::from(w) * u64::from(h) * size_of::<PixelSum>() as u64;
    prism_math::limits::check_memory(bytes).map_err(|source| PartError::OverBudget {
        file: files[0].path.clone(),
        width: w,
        height: h,
        source,
    })?;
    let mut sums = Image::new(w, h, PixelSum::default());
    for i in order {
        let file = &files[i];
        let layers = file.layers()?;
        // Straight from the channels into the sums: no second image per part.
        let mut overflow = None;
        each_pixel(&layers, &file.header, &file.path, |x, y, add| {
            let acc = &mut sums.pixels_mut()[(y * w + x) as usize];
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
            });
        }
    }
    Ok(Merged {
        identity: first.identity.clone(),
        sums,
        holes,
    })
}
