//! Lighting a scene by an environment map: [`Scene::light_by_environment_map`] checks the
//! map's radiance and puts it in place of the scene's hemisphere and environment lights.

use std::sync::Arc;

use prism_image::RgbImage;
use prism_math::{ExactSum, Rgb};

use crate::scene::{Light, Scene};

/// What an environment map may not hold.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum EnvironmentMapError {
    /// A texel that is not finite, is negative, or is 2^55 or more: the renderer would
    /// count its samples as black and make a wrong picture.
    #[error("texel ({x}, {y}) is {value:?}; expected finite, non-negative radiance below 2^55")]
    BadTexel {
        /// Column.
        x: u32,
        /// Row, 0 at the top.
        y: u32,
        /// The texel.
        value: Rgb,
    },
}

/// Whether a light is at infinity: a hemisphere, environment or environment-map light.
fn infinite(l: &Light) -> bool {
    matches!(
        l,
        Light::Hemisphere { .. } | Light::Environment { .. } | Light::EnvironmentMap { .. }
    )
}

impl Scene {
    /// Lights the scene by `map` (linear radiance, latitude-longitude): every hemisphere,
    /// environment or environment-map light is removed and the map added as the last light.
    /// Returns whether a light removed gave off light (callers say it was replaced).
    ///
    /// # Errors
    /// [`EnvironmentMapError::BadTexel`] for the first texel, row by row, whose radiance is
    /// not finite, is negative or is [`ExactSum::LIMIT`] or more; the scene is then
    /// unchanged.
    pub fn light_by_environment_map(
        &mut self,
        map: Arc<RgbImage>,
    ) -> Result<bool, EnvironmentMapError> {
        let within = |v: f32| (0.0..ExactSum::LIMIT).contains(&v);
        if let Some(i) = map
            .pixels()
            .iter()
            .position(|p| !(within(p.r) && within(p.g) && within(p.b)))
        {
            let (x, y) = (i as u32 % map.width(), i as u32 / map.width());
            return Err(EnvironmentMapError::BadTexel {
                x,
                y,
                value: map.get(x, y),
            });
        }
        let replaced = self
            .lights
            .iter()
            .any(|l| infinite(l) && l.gives_off_light());
        self.lights.retain(|l| !infinite(l));
        self.lights.push(Light::EnvironmentMap {
            radiance: map,
            mapping: crate::EnvMapping::Course,
        });
        Ok(replaced)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::builtin::cornell_box;

    fn map(texel: Rgb) -> Arc<RgbImage> {
        let mut m = RgbImage::new(4, 2, Rgb::new(0.5, 0.5, 0.5));
        m.set(3, 1, texel);
        Arc::new(m)
    }

    /// The map replaces every light at infinity and keeps the others, in order.
    #[test]
    fn map_replaces_lights_at_infinity() {
        let mut scene = cornell_box();
        let finite: Vec<Light> = scene
            .lights
            .iter()
            .filter(|l| !infinite(l))
            .cloned()
            .collect();
        scene.lights.push(Light::Hemisphere {
            radiance: Rgb::new(1.0, 1.0, 1.0),
        });
        let m = map(Rgb::new(1.0, 2.0, 3.0));
        assert_eq!(scene.light_by_environment_map(m.clone()), Ok(true));
        let mut expected = finite;
        expected.push(Light::EnvironmentMap {
            radiance: m,
            mapping: crate::EnvMapping::Course,
        });
        assert_eq!(scene.lights, expected);
        // A second map replaces the first, which gave off light.
        assert_eq!(
            scene.light_by_environment_map(map(Rgb::new(0.0, 0.0, 0.0))),
            Ok(true)
        );
        let mut dark = cornell_box();
        assert_eq!(
            dark.light_by_environment_map(map(Rgb::new(0.0, 0.0, 0.0))),
            Ok(false)
        );
    }

    /// NaN, negative and too-large texels are refused by position; the scene is unchanged.
    #[test]
    fn bad_texels_are_refused() {
        for bad in [f32::NAN, -1.0, ExactSum::LIMIT, f32::INFINITY] {
            let mut scene = cornell_box();
            let before = scene.lights.clone();
            let e = scene
                .light_by_environment_map(map(Rgb::new(0.0, bad, 0.0)))
                .unwrap_err();
            let EnvironmentMapError::BadTexel { x, y, .. } = e;
            assert_eq!((x, y), (3, 1));
            assert_eq!(scene.lights, before);
        }
    }
}
