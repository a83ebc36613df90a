//! [`PixelFilter`]: where in the image a pixel's samples fall. A box filter spreads them
//! uniformly over the pixel; a wider reconstruction filter (Mitsuba's `gaussian` and `tent`)
//! draws them from its own density around the pixel's centre, cut at the image's edges,
//! so that a pixel's expected value is the filter-weighted mean of the radiance around it,
//! which is what splatting samples with the filter's weights converges to.

use std::sync::Arc;

use prism_scene::Filter;

/// How a sample's image position is drawn for a pixel.
#[derive(Clone, Debug, Default)]
pub enum PixelFilter {
    /// Uniform over the pixel.
    #[default]
    Box,
    /// From a separable filter's density, tabulated.
    Table(Arc<FilterTable>),
}

impl PixelFilter {
    /// The sampling of `filter`.
    #[must_use]
    pub fn new(filter: &Filter) -> PixelFilter {
        match *filter {
            Filter::Box => PixelFilter::Box,
            Filter::Gaussian { stddev } => {
                // Mitsuba's windowed Gaussian: cut at four deviations, shifted to reach 0 there.
                let r = 4.0 * stddev;
                let alpha = -1.0 / (2.0 * stddev * stddev);
                let bias = (alpha * r * r).exp();
                PixelFilter::Table(Arc::new(FilterTable::new(
                    |x| ((alpha * x * x).exp() - bias).max(0.0),
                    r,
                )))
            }
            Filter::Tent { radius } => PixelFilter::Table(Arc::new(FilterTable::new(
                |x| (1.0 - x.abs() / radius).max(0.0),
                radius,
            ))),
        }
    }

    /// The image coordinate, along an axis of `len` pixels, of a sample of pixel `i` drawn
    /// with `u` in [0, 1).
    #[inline]
    #[must_use]
    pub fn position(&self, i: u32, u: f32, len: u32) -> f32 {
        match self {
            PixelFilter::Box => i as f32 + u,
            PixelFilter::Table(t) => {
                let centre = i as f32 + 0.5;
                let lo = (-t.radius).max(-centre);
                let hi = t.radius.min(len as f32 - centre);
                centre + t.sample(lo, hi, u)
            }
        }
    }
}

/// Bins of the table over [-radius, radius].
const BINS: usize = 1024;

/// A 1D filter's cumulative distribution over [-radius, radius], in [`BINS`] bins each
/// integrated by Simpson's rule, sampled by inversion with the density constant in a bin.
#[derive(Clone, Debug, PartialEq)]
pub struct FilterTable {
    radius: f32,
    /// `cdf[k]`: the normalised integral from -radius to the end of bin k - 1 (`cdf[0]` = 0).
    cdf: Vec<f32>,
}

impl FilterTable {
    /// The table of the non-negative filter `f` of support [-radius, radius].
    ///
    /// # Panics
    /// If `f` integrates to 0 there.
    #[must_use]
    pub fn new(f: impl Fn(f64) -> f64, radius: f64) -> FilterTable {
        let width = 2.0 * radius / BINS as f64;
        let mut cdf = Vec::with_capacity(BINS + 1);
        let mut sum = 0.0;
        cdf.push(0.0);
        for k in 0..BINS {
            let a = -radius + k as f64 * width;
            // Simpson's rule on eight sub-intervals.
            let h = width / 8.0;
            let mut s = f(a) + f(a + width);
            for j in 1..8 {
                s += f(a + j as f64 * h) * if j % 2 == 1 { 4.0 } else { 2.0 };
            }
            sum += s * h / 3.0;
            cdf.push(sum);
        }
        assert!(sum > 0.0, "a filter that integrates to 0");
        FilterTable {
            radius: radius as f32,
            cdf: cdf.into_iter().map(|c| (c / sum) as f32).collect(),
        }
    }

    /// The filter's radius.
    #[must_use]
    pub fn radius(&self) -> f32 {
        self.radius
    }

    /// The cumulative distribution at `x` in [-radius, radius].
    fn cdf_at(&self, x: f32) -> f32 {
        let t = ((x + self.radius) / (2.0 * self.radius) * BINS as f32).clamp(0.0, BINS as f32);
        let k = (t as usize).min(BINS - 1);
        let frac = t - k as f32;
        self.cdf[k] + (self.cdf[k + 1] - self.cdf[k]) * frac
    }

    /// An offset drawn from the filter's density cut to [lo, hi], with `u` in [0, 1).
    #[must_use]
    pub fn sample(&self, lo: f32, hi: f32, u: f32) -> f32 {
        let (c0, c1) = (self.cdf_at(lo), self.cdf_at(hi));
        let c = c0 + (c1 - c0) * u;
        // The first bin whose end passes c.
        let k = self.cdf[1..].partition_point(|&e| e < c).min(BINS - 1);
        let (a, b) = (self.cdf[k], self.cdf[k + 1]);
        let frac = if b > a { (c - a) / (b - a) } else { 0.5 };
        let width = 2.0 * self.radius / BINS as f32;
        (-self.radius + (k as f32 + frac) * width).clamp(lo, hi)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Closed forms: the tent's samples have the tent's mean |x| (r / 3), the Gaussian's the
    /// variance of the windowed density (integrated numerically), and a cut at an image edge
    /// keeps every sample inside the image.
    #[test]
    fn samples_follow_the_filter() {
        let n = 200_000;
        let tent = FilterTable::new(|x| (1.0 - x.abs()).max(0.0), 1.0);
        let mean_abs: f64 = (0..n)
            .map(|i| f64::from(tent.sample(-1.0, 1.0, (i as f32 + 0.5) / n as f32).abs()))
            .sum::<f64>()
            / f64::from(n);
        assert!((mean_abs - 1.0 / 3.0).abs() < 1e-3, "{mean_abs}");
        let (s, r) = (0.5f64, 2.0f64);
        let alpha = -1.0 / (2.0 * s * s);
        let bias = (alpha * r * r).exp();
        let f = |x: f64| ((alpha * x * x).exp() - bias).max(0.0);
        let gauss = FilterTable::new(f, r);
        let (mut m0, mut m2) = (0.0, 0.0);
        for i in 0..100_000 {
            let x = -r + (f64::from(i) + 0.5) * 2.0 * r / 100_000.0;
            m0 += f(x);
            m2 += f(x) * x * x;
        }
        let var: f64 = (0..n)
            .map(|i| f64::from(gauss.sample(-2.0, 2.0, (i as f32 + 0.5) / n as f32)).powi(2))
            .sum::<f64>()
            / f64::from(n);
        assert!((var / (m2 / m0) - 1.0).abs() < 2e-3, "{var} vs {}", m2 / m0);
        let filter = PixelFilter::Table(Arc::new(gauss));
        for i in 0..1000 {
            let u = i as f32 / 1000.0;
            let x = filter.position(0, u, 4);
            assert!((0.0..=4.0).contains(&x), "{x}");
        }
        // A box filter keeps the plain jitter, bit for bit.
        assert_eq!(PixelFilter::Box.position(7, 0.25, 10), 7.25);
    }
}
