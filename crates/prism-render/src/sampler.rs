//! [`Sampler`], the deterministic sampler: uniform samples as a pure function of (seed,
//! pixel, sample index, dimension).

use prism_math::{hash_words, unit_f32, Vec2};

/// Independent uniform samples whose values are a pure function of (seed, pixel, sample
/// index, dimension): the same picture whatever the thread count or tile order.
#[derive(Clone, Debug)]
pub struct Sampler {
    key: u64,
    dim: u64,
}

impl Sampler {
    /// The sampler of sample `index` of pixel `pixel`.
    #[must_use]
    pub fn new(seed: u64, pixel: u64, index: u64) -> Sampler {
        Sampler {
            key: hash_words(&[seed, pixel, index]),
            dim: 0,
        }
    }

    /// The next dimension's value in `[0, 1)`.
    pub fn next_1d(&mut self) -> f32 {
        let h = prism_math::mix64(self.key ^ self.dim.wrapping_mul(0x9e37_79b9_7f4a_7c15));
        self.dim += 1;
        unit_f32((h >> 32) as u32)
    }

    /// The next two dimensions.
    pub fn next_2d(&mut self) -> Vec2 {
        Vec2::new(self.next_1d(), self.next_1d())
    }
}
