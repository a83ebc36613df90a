//! The sensor, film, sampler and integrator of a Mitsuba scene: prism's camera and the
//! settings a render takes from the file.

use prism_math::glam::DVec3;

use super::document::Object;
use super::limits::{MAX_FILM_SIDE, MAX_SAMPLE_COUNT};
use super::props::{error, not_supported, unsupported};
use super::to_scene::{Builder, Filter};
use crate::error::SceneError;
use crate::scene::{Camera, Crop, ThinLens};

impl Builder<'_> {
    /// A sensor: the camera, and its film and sampler, if it is the one asked for (each is
    /// read, so that an error in any is reported).
    pub(super) fn sensor(&mut self, o: &Object) -> Result<(), SceneError> {
        let index = self.sensors;
        self.sensors += 1;
        let s = &self.settings;
        let kept = (self.scene.camera, s.size, s.filter, s.spp);
        self.read_sensor(o)?;
        if index != self.sensor_wanted {
            let s = &mut self.settings;
            (self.scene.camera, s.size, s.filter, s.spp) = kept;
        }
        Ok(())
    }

    /// [`Builder::sensor`]'s reading.
    fn read_sensor(&mut self, o: &Object) -> Result<(), SceneError> {
        if !matches!(o.kind.as_str(), "perspective" | "thinlens" | "orthographic") {
            return Err(unsupported(o));
        }
        let mut crop = None;
        for &(_, child) in &o.children {
            let c = &self.doc.objects[child];
            match c.tag.as_str() {
                "film" => crop = self.film(c)?,
                "sampler" => {
                    let n = c.integer("sample_count", 4)?;
                    if !(1..=i64::from(MAX_SAMPLE_COUNT)).contains(&n) {
                        return Err(error(
                            c,
                            format!(
                                "{}: sample_count: expected 1 to {MAX_SAMPLE_COUNT}, found {n}",
                                c.label()
                            ),
                        ));
                    }
                    self.settings.spp = n as u32;
                }
                _ => return Err(unsupported(c)),
            }
        }
        // The view is the whole film's, however it is cropped.
        let (w, h) = crop.map_or(self.settings.size, |c: Crop| c.full);
        let aspect = f64::from(w) / f64::from(h);
        let fov = match o.value("fov") {
            Some(_) => o.float("fov", 0.0)?,
            None => {
                // A 35 mm film's width over the focal length (Mitsuba's "50mm" default).
                let f = o.string("focal_length")?.unwrap_or("50mm");
                let mm: f64 = f.trim_end_matches("mm").trim().parse().map_err(|_| {
                    error(
                        o,
                        format!(
                            "{}: focal_length: expected millimetres such as \"50mm\", found {f:?}",
                            o.label()
                        ),
                    )
                })?;
                2.0 * (36.0 / (2.0 * mm)).atan().to_degrees()
            }
        };
        if !(fov > 0.0 && fov < 180.0) {
            return Err(error(
                o,
                format!(
                    "{}: fov: expected degrees strictly between 0 and 180, found {fov}",
                    o.label()
                ),
            ));
        }
        let axis = o.string("fov_axis")?.unwrap_or("x");
        let t = (fov.to_radians() * 0.5).tan();
        // The tangents of the half angles across and up the film.
        let (tx, ty) = match axis {
            "x" => (t, t / aspect),
            "y" => (t * aspect, t),
            "diagonal" => {
                let d = (1.0 + 1.0 / (aspect * aspect)).sqrt();
                (t / d, t / d / aspect)
            }
            "smaller" if aspect > 1.0 => (t * aspect, t),
            "smaller" => (t, t / aspect),
            "larger" if aspect > 1.0 => (t, t / aspect),
            "larger" => (t * aspect, t),
            other => {
                return Err(error(
                    o,
                    format!(
                        "{}: fov_axis: expected x, y, diagonal, smaller or larger, found {other:?}",
                        o.label()
                    ),
                ))
            }
        };
        let to_world = o.transform("to_world")?;
        let eye = to_world.transform_point3(DVec3::ZERO);
        let dir = to_world.transform_vector3(DVec3::Z);
        let up = to_world.transform_vector3(DVec3::Y);
        let left = to_world.transform_vector3(DVec3::X);
        if dir.length_squared() == 0.0 || up.length_squared() == 0.0 {
            return Err(error(
                o,
                format!("{}: to_world: the camera's axes are degenerate", o.label()),
            ));
        }
        // Mitsuba's camera has +x to the left; a to_world that mirrors it flips the picture.
        if up.cross(dir).dot(left) <= 0.0 {
            return Err(not_supported(
                o,
                format!(
                    "{}: to_world mirrors the image: not supported by prism yet",
                    o.label()
                ),
            ));
        }
        let near = o.float("near_clip", 1e-2)?;
        let far = o.float("far_clip", 1e4)?;
        if !(near > 0.0 && far > near) {
            return Err(error(
                o,
                format!(
                    "{}: near_clip and far_clip: expected 0 < near < far, found {near} and {far}",
                    o.label()
                ),
            ));
        }
        let lens = if o.kind == "thinlens" {
            let radius = o.float("aperture_radius", 0.0)?;
            let focus = o.float("focus_distance", 0.0)?;
            if !(radius >= 0.0 && focus > 0.0) {
                return Err(error(
                    o,
                    format!(
                        "{}: expected aperture_radius >= 0 and focus_distance > 0",
                        o.label()
                    ),
                ));
            }
            Some(ThinLens {
                radius: radius as f32,
                focal_distance: focus as f32,
            })
        } else {
            None
        };
        // Mitsuba's orthographic camera: parallel rays from its near plane, the film's width
        // spanning to_world's x axis twice and its height the y axis twice over the aspect.
        let (eye, orthographic) = if o.kind == "orthographic" {
            let plane = to_world.transform_point3(DVec3::new(0.0, 0.0, near));
            (plane, Some((left.length() as f32, up.length() as f32)))
        } else {
            (eye, None)
        };
        self.scene.camera = Camera {
            eye: eye.as_vec3(),
            target: (eye + dir.normalize()).as_vec3(),
            up: up.normalize().as_vec3(),
            hfov: (2.0 * tx.atan()).to_degrees() as f32,
            vfov: (2.0 * ty.atan()).to_degrees() as f32,
            near: near as f32,
            far: far as f32,
            lens,
            orthographic,
            crop,
        };
        Ok(())
    }

    /// The film: its size, its crop window (the image's size then) and its reconstruction
    /// filter.
    fn film(&mut self, o: &Object) -> Result<Option<Crop>, SceneError> {
        if o.kind != "hdrfilm" {
            return Err(unsupported(o));
        }
        let side = |name: &str, default: i64| -> Result<u32, SceneError> {
            let v = o.integer(name, default)?;
            if !(1..=i64::from(MAX_FILM_SIDE)).contains(&v) {
                return Err(error(
                    o,
                    format!(
                        "{}: {name}: expected 1 to {MAX_FILM_SIDE} pixels, found {v}",
                        o.label()
                    ),
                ));
            }
            Ok(v as u32)
        };
        let full = (side("width", 768)?, side("height", 576)?);
        let cropped = [
            "crop_offset_x",
            "crop_offset_y",
            "crop_width",
            "crop_height",
        ]
        .iter()
        .any(|n| o.value(n).is_some());
        let crop = if cropped {
            let at = |name: &str, default: u32| -> Result<u32, SceneError> {
                let v = o.integer(name, i64::from(default))?;
                u32::try_from(v).map_err(|_| {
                    error(
                        o,
                        format!(
                            "{}: {name}: expected a whole number of pixels, found {v}",
                            o.label()
                        ),
                    )
                })
            };
            let offset = (at("crop_offset_x", 0)?, at("crop_offset_y", 0)?);
            let size = (at("crop_width", full.0)?, at("crop_height", full.1)?);
            let fits =
                |o: u32, s: u32, f: u32| s >= 1 && u64::from(o) + u64::from(s) <= u64::from(f);
            if !fits(offset.0, size.0, full.0) || !fits(offset.1, size.1, full.1) {
                return Err(error(
                    o,
                    format!(
                        "{}: the crop window ({}x{} at {}, {}) must lie within the {}x{} film",
                        o.label(),
                        size.0,
                        size.1,
                        offset.0,
                        offset.1,
                        full.0,
                        full.1
                    ),
                ));
            }
            self.settings.size = size;
            Some(Crop { offset, full })
        } else {
            self.settings.size = full;
            None
        };
        for &(_, child) in &o.children {
            let c = &self.doc.objects[child];
            if c.tag != "rfilter" {
                return Err(unsupported(c));
            }
            self.settings.filter = match c.kind.as_str() {
                "box" => Filter::Box,
                "gaussian" => Filter::Gaussian {
                    stddev: c.float("stddev", 0.5)?,
                },
                "tent" => Filter::Tent {
                    radius: c.float("radius", 1.0)?,
                },
                _ => return Err(unsupported(c)),
            };
        }
        Ok(crop)
    }

    /// The integrator's depth settings.
    pub(super) fn integrator(&mut self, o: &Object) -> Result<(), SceneError> {
        self.settings.hide_emitters = o.boolean("hide_emitters", false)?;
        match o.kind.as_str() {
            "path" => {}
            // Mitsuba's `direct`: emission and one bounce of direct light, by light and BSDF
            // sampling under multiple importance sampling, as a path of one bounce is; its
            // sample counts change the noise only.
            "direct" => {
                self.settings.max_bounces = Some(1);
                return Ok(());
            }
            _ => return Err(unsupported(o)),
        }
        let max_depth = o.integer("max_depth", -1)?;
        self.settings.max_bounces = match max_depth {
            -1 => None,
            d if (1..=1024).contains(&d) => Some(d as u32 - 1),
            d => {
                return Err(error(
                    o,
                    format!(
                        "{}: max_depth: expected -1 or 1 to 1024, found {d}",
                        o.label()
                    ),
                ))
            }
        };
        let rr = o.integer("rr_depth", 5)?;
        if !(1..=1024).contains(&rr) {
            return Err(error(
                o,
                format!("{}: rr_depth: expected 1 to 1024, found {rr}", o.label()),
            ));
        }
        self.settings.rr_bounces = rr as u32;
        Ok(())
    }
}
