//! [`Orbit`]: a camera turned about its target by mouse drags and moved closer by the wheel,
//! shared by the modes that show a 3D scene.

use prism_math::Vec3;

use crate::input::Input;

/// Turns about a target: yaw and pitch added to a camera's own (radians), and a scale of its
/// distance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orbit {
    /// Added turn about the vertical axis.
    pub yaw: f32,
    /// Added elevation.
    pub pitch: f32,
    /// Distance scale.
    pub scale: f32,
    drag: Option<(f64, f64)>,
    cursor: (f64, f64),
}

impl Default for Orbit {
    fn default() -> Orbit {
        Orbit {
            yaw: 0.0,
            pitch: 0.0,
            scale: 1.0,
            drag: None,
            cursor: (0.0, 0.0),
        }
    }
}

impl Orbit {
    /// True if the orbit leaves a camera where it is.
    #[must_use]
    pub fn is_identity(&self) -> bool {
        (self.yaw, self.pitch, self.scale) == (0.0, 0.0, 1.0)
    }

    /// Back to the camera's own place.
    pub fn reset(&mut self) {
        *self = Orbit::default();
    }

    /// The cursor moved to `(x, y)` in a window `width` pixels wide; true if a drag turned the
    /// orbit (half a turn across the window's width).
    pub fn cursor(&mut self, x: f64, y: f64, width: u32) -> bool {
        self.cursor = (x, y);
        let Some((px, py)) = self.drag else {
            return false;
        };
        let per_pixel = std::f32::consts::PI / width.max(1) as f32;
        self.yaw -= (x - px) as f32 * per_pixel;
        self.pitch += (y - py) as f32 * per_pixel;
        self.drag = Some((x, y));
        true
    }

    /// The left button went down or up.
    pub fn button(&mut self, down: bool) {
        self.drag = down.then_some(self.cursor);
    }

    /// The wheel turned `lines`: each line away from the user brings the camera 10% closer.
    pub fn wheel(&mut self, lines: f64) {
        self.scale = (self.scale * 0.9f32.powf(lines as f32)).clamp(0.05, 20.0);
    }

    /// Takes the mouse's inputs (cursor, left button, wheel) in a window `width` pixels
    /// wide: `Some(true)` if the orbit moved, `Some(false)` if not, `None` for any other
    /// input.
    pub fn input(&mut self, input: &Input, width: u32) -> Option<bool> {
        match *input {
            Input::Cursor { x, y } => Some(self.cursor(x, y, width)),
            Input::Button(down) => {
                self.button(down);
                Some(false)
            }
            Input::Wheel(lines) => {
                self.wheel(lines);
                Some(true)
            }
            Input::Key { .. } | Input::Resize { .. } => None,
        }
    }

    /// The eye of a camera at `eye` looking at `target` (Y up), after the orbit; exactly
    /// `eye` when the orbit is the identity. The elevation stays within 89 degrees.
    #[must_use]
    pub fn eye(&self, eye: Vec3, target: Vec3) -> Vec3 {
        if self.is_identity() {
            return eye;
        }
        let d = eye - target;
        let r = d.length();
        let yaw = d.x.atan2(d.z) + self.yaw;
        let limit = 89f32.to_radians();
        let pitch =
            ((d.y / r.max(1e-12)).clamp(-1.0, 1.0).asin() + self.pitch).clamp(-limit, limit);
        let dir = Vec3::new(
            pitch.cos() * yaw.sin(),
            pitch.sin(),
            pitch.cos() * yaw.cos(),
        );
        target + dir * (r * self.scale)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Closed form: a quarter turn of yaw takes an eye on +z to +x at the same distance; the
    /// identity leaves the eye's bits alone; the wheel scales the distance.
    #[test]
    fn orbit_turns_about_the_target() {
        let target = Vec3::new(1.0, 2.0, 3.0);
        let eye = target + Vec3::new(0.0, 0.0, 5.0);
        let mut o = Orbit::default();
        assert_eq!(o.eye(eye, target), eye);
        o.yaw = std::f32::consts::FRAC_PI_2;
        let e = o.eye(eye, target);
        assert!((e - (target + Vec3::new(5.0, 0.0, 0.0))).length() < 1e-5);
        o.reset();
        o.wheel(1.0);
        assert!(((o.eye(eye, target) - target).length() - 4.5).abs() < 1e-5);
        o.reset();
        o.cursor(10.0, 10.0, 100);
        o.button(true);
        assert!(o.cursor(60.0, 10.0, 100));
        assert!((o.yaw + std::f32::consts::FRAC_PI_2).abs() < 1e-6);
        o.button(false);
        assert!(!o.cursor(0.0, 0.0, 100));
    }
}
