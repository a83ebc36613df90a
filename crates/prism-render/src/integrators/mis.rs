//! The multiple-importance-sampling weight the integrators share.

/// Power heuristic with exponent 2 for `nf` samples of density `f` against one of `g`.
pub(super) fn power(nf: f32, f: f32, g: f32) -> f32 {
    let a = nf * f;
    if a == 0.0 && g == 0.0 {
        return 0.0;
    }
    a * a / (a * a + g * g)
}
