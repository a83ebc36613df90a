//! [`PartIdentity`]: what a split render is, as a typed value. Every setting that changes
//! pixels is in it; a part file stores it as named strings ([`PartIdentity::to_attributes`])
//! and `prism merge` reads it back ([`PartIdentity::from_attributes`]).

use prism_image::Bloom;
use prism_scene::{Filter, OrbitCamera};

use crate::integrators::Integrator;
use crate::render::RenderOptions;
use crate::whitted::film::{rays_per_pixel, RaytraceOptions};

/// The version of prism that writes parts: parts of different versions do not merge.
const VERSION: &str = env!("CARGO_PKG_VERSION");

/// How a render's linear values become the bytes of a picture.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Encoding {
    /// The sRGB curve, rounded (the path tracer's pictures).
    Srgb,
    /// Clamped and truncated, byte = trunc(255 v), no gamma (the Delft ray tracer's).
    Truncated,
}

impl Encoding {
    /// The name a part records: `srgb` or `truncated`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Encoding::Srgb => "srgb",
            Encoding::Truncated => "truncated",
        }
    }
}

/// The settings particular to the renderer that made a part.
#[derive(Clone, Debug, PartialEq)]
pub enum Renderer {
    /// The path tracer (`prism render`, kind `render`).
    Path {
        /// Samples per area or hemisphere light per shading point.
        light_samples: u32,
        /// Most bounces a path takes.
        max_bounces: u32,
        /// The estimator; [`Integrator::PathScalar`] is recorded as [`Integrator::Path`],
        /// whose bytes it equals.
        integrator: Integrator,
        /// The only bounce kept, if one is.
        only_bounce: Option<u32>,
        /// Adaptive sampling's tolerance and batch, when on.
        adaptive: Option<(f32, u32)>,
        /// Bounces before Russian roulette may end a path.
        rr_bounces: u32,
        /// Emitters hidden from the camera (written only when on).
        hide_emitters: bool,
        /// One light picked per light sample (written only when on).
        one_light: bool,
        /// The reconstruction filter (written only when not a box).
        filter: Filter,
    },
    /// The Delft Whitted ray tracer (`prism raytrace`, kind `raytrace`).
    Whitted {
        /// The orbit camera, in its `Debug` form (compared, never parsed).
        camera: String,
        /// The feature switches, light samples and depth, in their `Debug` form (compared,
        /// never parsed).
        settings: String,
        /// The bloom `prism merge` adds, when on.
        bloom: Option<Bloom>,
    },
}

/// A render's identity: every setting that changes its pixels. The parts of one split
/// render share it, and parts whose identities differ do not merge.
#[derive(Clone, Debug, PartialEq)]
pub struct PartIdentity {
    /// The version of prism that rendered.
    pub version: String,
    /// The scene's fingerprint ([`prism_scene::Scene::fingerprint`]), which covers its
    /// camera, lens, normals and lights.
    pub scene: u64,
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Samples (rays) per pixel of the whole render.
    pub spp: u32,
    /// Seed of every random number.
    pub seed: u64,
    /// The renderer and its own settings.
    pub renderer: Renderer,
}

/// What is wrong with a set of identity settings.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum IdentityError {
    /// A setting the render's kind needs is absent.
    #[error("no setting {key}")]
    Missing {
        /// The setting.
        key: &'static str,
    },
    /// A setting's value is malformed.
    #[error("setting {key} is `{value}`; expected {expected}")]
    Malformed {
        /// The setting.
        key: String,
        /// Its value.
        value: String,
        /// What was expected.
        expected: &'static str,
    },
    /// A setting no render of its kind has.
    #[error("setting {key} belongs to no {kind} render")]
    Unexpected {
        /// The setting.
        key: String,
        /// The render's kind.
        kind: &'static str,
    },
}

impl PartIdentity {
    /// The identity of a path-traced render of the scene whose fingerprint is `scene`.
    #[must_use]
    pub fn path(scene: u64, opts: &RenderOptions) -> PartIdentity {
        let integrator = match opts.path.integrator {
            Integrator::PathScalar => Integrator::Path,
            other => other,
        };
        PartIdentity {
            version: VERSION.to_string(),
            scene,
            width: opts.film.width,
            height: opts.film.height,
            spp: opts.film.spp,
            seed: opts.film.seed,
            renderer: Renderer::Path {
                light_samples: opts.path.light_samples,
                max_bounces: opts.path.max_bounces,
                integrator,
                only_bounce: opts.path.only_bounce,
                adaptive: opts.film.adaptive.map(|t| (t, opts.film.batch)),
                rr_bounces: opts.path.rr_bounces,
                hide_emitters: opts.path.hide_emitters,
                one_light: opts.path.one_light,
                filter: opts.film.filter,
            },
        }
    }

    /// The identity of a Whitted render of the scene whose fingerprint is `scene`, seen
    /// from `camera`; its samples are the rays each pixel casts.
    #[must_use]
    pub fn whitted(scene: u64, camera: &OrbitCamera, opts: &RaytraceOptions) -> PartIdentity {
        PartIdentity {
            version: VERSION.to_string(),
            scene,
            width: opts.width,
            height: opts.height,
            spp: rays_per_pixel(opts),
            seed: opts.seed,
            renderer: Renderer::Whitted {
                camera: format!("{camera:?}"),
                settings: format!("{:?}", opts.settings),
                bloom: opts.settings.features.bloom.then_some(opts.bloom),
            },
        }
    }

    /// The kind of render: `render` (path tracer) or `raytrace` (Whitted).
    #[must_use]
    pub fn kind(&self) -> &'static str {
        match self.renderer {
            Renderer::Path { .. } => "render",
            Renderer::Whitted { .. } => "raytrace",
        }
    }

    /// How the merged picture is encoded: sRGB for the path tracer, truncated for Whitted.
    #[must_use]
    pub fn encoding(&self) -> Encoding {
        match self.renderer {
            Renderer::Path { .. } => Encoding::Srgb,
            Renderer::Whitted { .. } => Encoding::Truncated,
        }
    }

    /// The bloom a merged Whitted picture gets, if on.
    #[must_use]
    pub fn bloom(&self) -> Option<Bloom> {
        match self.renderer {
            Renderer::Whitted { bloom, .. } => bloom,
            Renderer::Path { .. } => None,
        }
    }

    /// The identity as named settings, the form [`super::Part::new`] takes and a part file
    /// stores (each as attribute `prism.<name>`): `kind`, `version`, `scene` (16 hex digits),
    /// `width`, `height`, `spp`, `seed`, `encoding`, then the renderer's own: for the path
    /// tracer `light_samples`, `max_bounces`, `integrator` (`path`, `normals` or
    /// `direct hemisphere=B`), `only_bounce` and `adaptive` (`TOL batch=N`; both `off` when
    /// not set), `rr_bounces`, and when on `hide_emitters` (`on`), `light_choice` (`one`) and `filter`
    /// (`gaussian STDDEV` or `tent RADIUS`, for other than a box); for Whitted `camera`, `settings` and `bloom`
    /// (`THRESHOLD PASSES`, or `off`).
    #[must_use]
    pub fn to_attributes(&self) -> Vec<(String, String)> {
        let off = |v: Option<String>| v.unwrap_or_else(|| "off".into());
        let mut out = vec![
            ("kind", self.kind().to_string()),
            ("version", self.version.clone()),
            ("scene", format!("{:016x}", self.scene)),
            ("width", self.width.to_string()),
            ("height", self.height.to_string()),
            ("spp", self.spp.to_string()),
            ("seed", self.seed.to_string()),
            ("encoding", self.encoding().name().to_string()),
        ];
        match &self.renderer {
            Renderer::Path {
                light_samples,
                max_bounces,
                integrator,
                only_bounce,
                adaptive,
                rr_bounces,
                hide_emitters,
                one_light,
                filter,
            } => {
                let integrator = match integrator {
                    Integrator::Path | Integrator::PathScalar => "path".to_string(),
                    Integrator::Direct { hemisphere } => format!("direct hemisphere={hemisphere}"),
                    Integrator::Normals => "normals".to_string(),
                };
                out.extend([
                    ("light_samples", light_samples.to_string()),
                    ("max_bounces", max_bounces.to_string()),
                    ("integrator", integrator),
                    ("only_bounce", off(only_bounce.map(|m| m.to_string()))),
                    (
                        "adaptive",
                        off(adaptive.map(|(t, batch)| format!("{t} batch={batch}"))),
                    ),
                    ("rr_bounces", rr_bounces.to_string()),
                ]);
                if *hide_emitters {
                    out.push(("hide_emitters", "on".to_string()));
                }
                if *one_light {
                    out.push(("light_choice", "one".to_string()));
                }
                match filter {
                    Filter::Box => {}
                    Filter::Gaussian { stddev } => {
                        out.push(("filter", format!("gaussian {stddev}")))
                    }
                    Filter::Tent { radius } => out.push(("filter", format!("tent {radius}"))),
                }
            }
            Renderer::Whitted {
                camera,
                settings,
                bloom,
            } => {
                out.extend([
                    ("camera", camera.clone()),
                    ("settings", settings.clone()),
                    (
                        "bloom",
                        off(bloom.map(|b| format!("{} {}", b.threshold, b.passes))),
                    ),
                ]);
            }
        }
        out.into_iter().map(|(k, v)| (k.to_string(), v)).collect()
    }

    /// The identity held in named settings, as [`PartIdentity::to_attributes`] writes them
    /// (in any order).
    ///
    /// # Errors
    /// [`IdentityError::Missing`] without a setting the kind needs,
    /// [`IdentityError::Malformed`] for a value that does not parse (or an unknown kind, or
    /// an encoding other than the kind's), [`IdentityError::Unexpected`] for a setting the
    /// kind does not have.
    pub fn from_attributes(settings: &[(String, String)]) -> Result<PartIdentity, IdentityError> {
        let text = |key: &'static str| read(settings, key, "", |v| Some(v.to_string()));
        let number = |key: &'static str| read(settings, key, "a whole number", |v| v.parse().ok());
        let renderer = match text("kind")?.as_str() {
            "render" => Renderer::Path {
                light_samples: number("light_samples")?,
                max_bounces: number("max_bounces")?,
                integrator: read(
                    settings,
                    "integrator",
                    "path, normals or direct hemisphere=B",
                    parse_integrator,
                )?,
                only_bounce: read(settings, "only_bounce", "a whole number or off", |v| {
                    parse_off(v, |v| v.parse().ok())
                })?,
                adaptive: read(settings, "adaptive", "TOL batch=N or off", |v| {
                    parse_off(v, parse_adaptive)
                })?,
                rr_bounces: number("rr_bounces")?,
                hide_emitters: settings.iter().any(|(k, _)| k == "hide_emitters")
                    && read(settings, "hide_emitters", "on", |v| {
                        (v == "on").then_some(true)
                    })?,
                one_light: settings.iter().any(|(k, _)| k == "light_choice")
                    && read(settings, "light_choice", "one", |v| {
                        (v == "one").then_some(true)
                    })?,
                filter: if settings.iter().any(|(k, _)| k == "filter") {
                    read(
                        settings,
                        "filter",
                        "gaussian STDDEV or tent RADIUS",
                        parse_filter,
                    )?
                } else {
                    Filter::Box
                },
            },
            "raytrace" => Renderer::Whitted {
                camera: text("camera")?,
                settings: text("settings")?,
                bloom: read(settings, "bloom", "THRESHOLD PASSES or off", |v| {
                    parse_off(v, parse_bloom)
                })?,
            },
            other => {
                return Err(IdentityError::Malformed {
                    key: "kind".into(),
                    value: other.into(),
                    expected: "render or raytrace",
                })
            }
        };
        let identity = PartIdentity {
            version: text("version")?,
            scene: read(settings, "scene", "16 hexadecimal digits", |v| {
                u64::from_str_radix(v, 16).ok().filter(|_| v.len() == 16)
            })?,
            width: number("width")?,
            height: number("height")?,
            spp: number("spp")?,
            seed: read(settings, "seed", "a whole number", |v| v.parse().ok())?,
            renderer,
        };
        let encoding = identity.encoding().name();
        read(settings, "encoding", encoding, |v| {
            (v == encoding).then_some(())
        })?;
        let known = identity.to_attributes();
        if let Some((key, _)) = settings
            .iter()
            .find(|(k, _)| !known.iter().any(|(n, _)| n == k))
        {
            return Err(IdentityError::Unexpected {
                key: key.clone(),
                kind: identity.kind(),
            });
        }
        Ok(identity)
    }
}

/// Setting `key` of `settings`, read by `parse`; `expected` says what `parse` reads.
fn read<T>(
    settings: &[(String, String)],
    key: &'static str,
    expected: &'static str,
    parse: impl Fn(&str) -> Option<T>,
) -> Result<T, IdentityError> {
    let (_, value) = settings
        .iter()
        .find(|(k, _)| k == key)
        .ok_or(IdentityError::Missing { key })?;
    parse(value).ok_or_else(|| IdentityError::Malformed {
        key: key.to_string(),
        value: value.clone(),
        expected,
    })
}

/// `off` as `Some(None)`, else the value `parse` reads, `None` if it reads none.
fn parse_off<T>(v: &str, parse: impl Fn(&str) -> Option<T>) -> Option<Option<T>> {
    if v == "off" {
        Some(None)
    } else {
        parse(v).map(Some)
    }
}

/// `gaussian STDDEV` or `tent RADIUS` (positive and finite).
fn parse_filter(v: &str) -> Option<Filter> {
    let (kind, size) = v.split_once(' ')?;
    let size: f64 = size
        .parse()
        .ok()
        .filter(|s: &f64| s.is_finite() && *s > 0.0)?;
    match kind {
        "gaussian" => Some(Filter::Gaussian { stddev: size }),
        "tent" => Some(Filter::Tent { radius: size }),
        _ => None,
    }
}

/// `path`, `normals` or `direct hemisphere=B`.
fn parse_integrator(v: &str) -> Option<Integrator> {
    match v {
        "path" => Some(Integrator::Path),
        "normals" => Some(Integrator::Normals),
        _ => {
            let b = v.strip_prefix("direct hemisphere=")?;
            Some(Integrator::Direct {
                hemisphere: b.parse().ok()?,
            })
        }
    }
}

/// `TOL batch=N`.
fn parse_adaptive(v: &str) -> Option<(f32, u32)> {
    let (t, b) = v.split_once(" batch=")?;
    Some((t.parse().ok()?, b.parse().ok()?))
}

/// `THRESHOLD PASSES`.
fn parse_bloom(v: &str) -> Option<Bloom> {
    let (t, p) = v.split_once(' ')?;
    Some(Bloom {
        threshold: t.parse().ok()?,
        passes: p.parse().ok()?,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn path() -> PartIdentity {
        PartIdentity {
            version: "0.1.0".into(),
            scene: 0x0123_4567_89ab_cdef,
            width: 64,
            height: 48,
            spp: 16,
            seed: 7,
            renderer: Renderer::Path {
                light_samples: 2,
                max_bounces: 5,
                integrator: Integrator::Direct { hemisphere: true },
                only_bounce: Some(3),
                adaptive: Some((0.05, 32)),
                rr_bounces: 5,
                hide_emitters: true,
                one_light: true,
                filter: Filter::Gaussian { stddev: 0.5 },
            },
        }
    }

    fn whitted() -> PartIdentity {
        PartIdentity {
            version: "0.1.0".into(),
            scene: 42,
            width: 10,
            height: 20,
            spp: 1,
            seed: u64::MAX,
            renderer: Renderer::Whitted {
                camera: "OrbitCamera { distance: 1.0 }".into(),
                settings: "WhittedSettings { max_depth: 3 }".into(),
                bloom: Some(Bloom {
                    threshold: 0.75,
                    passes: 3,
                }),
            },
        }
    }

    /// Oracle: every identity written is the one read back, in any order of its settings.
    #[test]
    fn attributes_round_trip() {
        let mut cases = vec![path(), whitted()];
        for integrator in [Integrator::Path, Integrator::Normals] {
            let mut p = path();
            if let Renderer::Path {
                integrator: i,
                only_bounce,
                adaptive,
                ..
            } = &mut p.renderer
            {
                *i = integrator;
                *only_bounce = None;
                *adaptive = None;
            }
            cases.push(p);
        }
        let mut w = whitted();
        if let Renderer::Whitted { bloom, .. } = &mut w.renderer {
            *bloom = None;
        }
        cases.push(w);
        for id in cases {
            let mut attributes = id.to_attributes();
            assert_eq!(PartIdentity::from_attributes(&attributes), Ok(id.clone()));
            attributes.reverse();
            assert_eq!(PartIdentity::from_attributes(&attributes), Ok(id));
        }
    }

    /// Oracle: the settings written are those part files have always held, by name.
    #[test]
    fn attributes_are_the_part_file_settings() {
        let a = path().to_attributes();
        let get = |k: &str| a.iter().find(|(n, _)| n == k).map(|(_, v)| v.as_str());
        let get_path = get;
        assert_eq!(get("kind"), Some("render"));
        assert_eq!(get("scene"), Some("0123456789abcdef"));
        assert_eq!(get("integrator"), Some("direct hemisphere=true"));
        assert_eq!(get("adaptive"), Some("0.05 batch=32"));
        assert_eq!(get("encoding"), Some("srgb"));
        let a = whitted().to_attributes();
        let get = |k: &str| a.iter().find(|(n, _)| n == k).map(|(_, v)| v.as_str());
        assert_eq!(get("scene"), Some("000000000000002a"));
        assert_eq!(get("bloom"), Some("0.75 3"));
        assert_eq!(get("encoding"), Some("truncated"));
        assert_eq!(a.len(), 11);
        // `hide_emitters` and `light_choice` are written only when on, so that older parts
        // still read.
        assert_eq!(get_path("hide_emitters"), Some("on"));
        assert_eq!(get_path("light_choice"), Some("one"));
        assert_eq!(get_path("filter"), Some("gaussian 0.5"));
        assert_eq!(path().to_attributes().len(), 17);
        let mut shown = path();
        if let Renderer::Path {
            hide_emitters,
            one_light,
            filter,
            ..
        } = &mut shown.renderer
        {
            *hide_emitters = false;
            *one_light = false;
            *filter = Filter::Box;
        }
        assert_eq!(shown.to_attributes().len(), 14);
    }

    /// A scalar path render records the same identity as the wavefront one.
    #[test]
    fn scalar_path_is_recorded_as_path() {
        let mut opts = RenderOptions::default();
        opts.path.integrator = Integrator::PathScalar;
        let scalar = PartIdentity::path(1, &opts);
        opts.path.integrator = Integrator::Path;
        assert_eq!(scalar, PartIdentity::path(1, &opts));
    }

    /// Missing, malformed and foreign settings are refused by name.
    #[test]
    fn bad_settings_are_refused() {
        let good = whitted().to_attributes();
        let without: Vec<_> = good.iter().filter(|(k, _)| k != "seed").cloned().collect();
        assert_eq!(
            PartIdentity::from_attributes(&without),
            Err(IdentityError::Missing { key: "seed" })
        );
        let set = |key: &str, value: &str| {
            let mut a = good.clone();
            a.iter_mut().find(|(k, _)| k == key).unwrap().1 = value.into();
            PartIdentity::from_attributes(&a)
        };
        for (key, value) in [
            ("bloom", "bright"),
            ("encoding", "srgb"),
            ("kind", "sketch"),
            ("scene", "2a"),
            ("width", "-1"),
        ] {
            assert!(
                matches!(set(key, value), Err(IdentityError::Malformed { .. })),
                "{key}={value}"
            );
        }
        let mut extra = good;
        extra.push(("integrator".into(), "path".into()));
        assert!(matches!(
            PartIdentity::from_attributes(&extra),
            Err(IdentityError::Unexpected { .. })
        ));
    }
}
