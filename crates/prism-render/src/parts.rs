//! Split renders: the [`Part`] file one share of a render writes (an OpenEXR file with the
//! mean radiance, each pixel's sums and sample count, and the render's identity as string
//! attributes), and [`merge`], which checks that a set of parts makes one whole render and
//! adds them up.

use std::path::{Path, PathBuf};

use prism_image::{ExrLayers, ExrSamples, Image, ImageError};
use prism_math::Rgb;

use crate::film::{tile_of, tiles, PixelSum, Share, TILE};

/// Attribute-name prefix of a part's identity and share.
const PREFIX: &str = "prism.";
/// The share's attributes: `I/N` and `A..B`.
const PART: &str = "prism.part";
const SAMPLES: &str = "prism.samples";
/// Identity keys every part has: what it renders, its size and its samples per pixel.
const REQUIRED: [&str; 4] = ["kind", "width", "height", "spp"];

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
}

/// One share of a render: its identity (every setting that changes pixels, by name), the
/// share, and each pixel's sums (pixels outside the share hold none).
#[derive(Clone, Debug, PartialEq)]
pub struct Part {
    /// Settings by name (`kind`, `width`, `height`, `spp`, `scene`, ...), sorted by name.
    pub identity: Vec<(String, String)>,
    /// The tiles and samples this part holds.
    pub share: Share,
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
            identity,
            share,
            sums,
        }
    }

    /// The identity setting `key`.
    #[must_use]
    pub fn setting(&self, key: &str) -> Option<&str> {
        self.identity
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }

    /// The part as OpenEXR channels and attributes: `R`, `G`, `B` the mean radiance (what
    /// other tools show), `sum.R`, `sum.G`, `sum.B` the radiance sums, `Y.sum` and
    /// `Y.sumsq` the luminance moments (rounded to 32-bit floats), `samples` the sample count;
    /// attributes `prism.<key>` for the identity, `prism.part` (`I/N`) and `prism.samples`
    /// (`A..B`).
    #[must_use]
    pub fn to_exr(&self) -> ExrLayers {
        let p = self.sums.pixels();
        let float = |f: &dyn Fn(&PixelSum) -> f32| ExrSamples::Float(p.iter().map(f).collect());
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
        ExrLayers {
            width: self.sums.width(),
            height: self.sums.height(),
            channels: vec![
                ("R".into(), float(&|s| s.mean().r)),
                ("G".into(), float(&|s| s.mean().g)),
                ("B".into(), float(&|s| s.mean().b)),
                ("sum.R".into(), float(&|s| s.sum.r)),
                ("sum.G".into(), float(&|s| s.sum.g)),
                ("sum.B".into(), float(&|s| s.sum.b)),
                ("Y.sum".into(), float(&|s| s.moment1 as f32)),
                ("Y.sumsq".into(), float(&|s| s.moment2 as f32)),
                (
                    "samples".into(),
                    ExrSamples::Uint(p.iter().map(|s| s.n).collect()),
                ),
            ],
            attributes,
        }
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
        let samples_text = attribute(SAMPLES)?;
        let samples = samples_text
            .split_once("..")
            .and_then(|(a, b)| Some(a.parse::<u32>().ok()?..b.parse::<u32>().ok()?))
            .filter(|r| r.start < r.end && r.end <= spp)
            .ok_or_else(|| bad(SAMPLES, samples_text, "A..B with 0 <= A < B <= prism.spp"))?;
        let float = |name: &str| match layers.channel(name) {
            Some(ExrSamples::Float(v)) => Ok(v),
            _ => Err(not_a_part(&format!("float channel {name}"))),
        };
        let (r, g, b) = (float("sum.R")?, float("sum.G")?, float("sum.B")?);
        let (m1, m2) = (float("Y.sum")?, float("Y.sumsq")?);
        let Some(ExrSamples::Uint(n)) = layers.channel("samples") else {
            return Err(not_a_part("uint channel samples"));
        };
        let share = Share {
            part,
            parts,
            samples,
        };
        let most = share.samples.len() as u32;
        let mut sums = Image::new(width, height, PixelSum::default());
        for y in 0..height {
            for x in 0..width {
                let i = (y * width + x) as usize;
                let s = PixelSum {
                    sum: Rgb::new(r[i], g[i], b[i]),
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
                if !(s.sum.is_finite() && s.moment1.is_finite() && s.moment2.is_finite()) {
                    return Err(corrupt("holds a sum that is not finite".into()));
                }
                sums.set(x, y, s);
            }
        }
        Ok(Part {
            identity,
            share,
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

/// Checks that `parts` (each with the file it came from) are shares of one render, every
/// tile and sample exactly once, and adds them up. Each pixel adds its parts in the order of
/// their first sample, whatever the order given, so a tile split gives exactly the sums of
/// the whole render. With `allow_missing`, missing shares are listed in
/// [`Merged::holes`] instead of refused.
///
/// # Errors
/// [`PartError::NoParts`] for an empty set, [`PartError::Mismatch`] for parts of
/// different renders or splits, [`PartError::Doubled`] for work held twice,
/// [`PartError::Missing`] for work held nowhere.
pub fn merge(parts: &[(PathBuf, Part)], allow_missing: bool) -> Result<Merged, PartError> {
    let Some((first_file, first)) = parts.first() else {
        return Err(PartError::NoParts);
    };
    for (file, p) in &parts[1..] {
        let mismatch = |key: &str, found: String, expected: String| PartError::Mismatch {
            file: file.clone(),
            key: key.to_string(),
            found,
            first: first_file.clone(),
            expected,
        };
        let keys: std::collections::BTreeSet<&str> = first
            .identity
            .iter()
            .chain(&p.identity)
            .map(|(k, _)| k.as_str())
            .collect();
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
    let mut order: Vec<usize> = (0..parts.len()).collect();
    order.sort_by_key(|&i| (parts[i].1.share.part, parts[i].1.share.samples.start));
    let mut holes = Vec::new();
    let describe = |part: u32, a: u32, b: u32| format!("tiles {part}/{count}, samples {a}..{b}");
    for share in 0..count {
        let mut next = 0u32;
        let mut last: Option<usize> = None;
        for &i in order.iter().filter(|&&i| parts[i].1.share.part == share) {
            let r = &parts[i].1.share.samples;
            if r.start < next {
                let j = last.expect("an earlier part set `next`");
                return Err(PartError::Doubled {
                    first: parts[j].0.clone(),
                    second: parts[i].0.clone(),
                    what: describe(share, r.start, next.min(r.end)),
                });
            }
            if r.start > next {
                holes.push(describe(share, next, r.start));
            }
            next = r.end;
            last = Some(i);
        }
        if next < spp {
            holes.push(describe(share, next, spp));
        }
    }
    if !holes.is_empty() && !allow_missing {
        return Err(PartError::Missing { holes });
    }
    let (w, h) = (first.sums.width(), first.sums.height());
    let mut sums = Image::new(w, h, PixelSum::default());
    for (k, &(x0, y0)) in tiles(w, h).iter().enumerate() {
        let share = (k % count as usize) as u32;
        for &i in order.iter().filter(|&&i| parts[i].1.share.part == share) {
            let part = &parts[i].1.sums;
            for y in y0..(y0 + TILE).min(h) {
                for x in x0..(x0 + TILE).min(w) {
                    let mut acc = sums.get(x, y);
                    if acc.n == 0 {
                        acc = part.get(x, y);
                    } else {
                        acc.merge(&part.get(x, y));
                    }
                    sums.set(x, y, acc);
                }
            }
        }
    }
    Ok(Merged {
        identity: first.identity.clone(),
        sums,
        holes,
    })
}
