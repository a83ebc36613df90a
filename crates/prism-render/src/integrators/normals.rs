//! The normals integrator: the shading normal at the first hit as a colour.

use prism_math::Rgb;

use crate::interaction::Interaction;

/// The shading normal `n` at `hit` as the colour `(n + 1) / 2`.
pub(super) fn normals(hit: &Interaction) -> Rgb {
    let n = hit.ns;
    Rgb::new(n.x * 0.5 + 0.5, n.y * 0.5 + 0.5, n.z * 0.5 + 0.5)
}
