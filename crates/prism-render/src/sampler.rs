//! [`Sampler`], the deterministic sampler: uniform samples as a pure function of (seed,
//! pixel, sample index, dimension).

use prism_math::lanes::{F16, LANES};
use prism_math::{hash_extend, hash_words, unit_f32, word_mix, Vec2};

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

    /// The part of [`Sampler::new`]'s key that the sample index does not change: with it,
    /// [`Sampler::from_pixel_key`] starts each of a pixel's samples with one mix.
    #[must_use]
    pub fn pixel_key(seed: u64, pixel: u64) -> u64 {
        hash_words(&[seed, pixel])
    }

    /// [`Sampler::new`] from the pixel's [`Sampler::pixel_key`]: the same sampler.
    #[must_use]
    pub fn from_pixel_key(pixel_key: u64, index: u64) -> Sampler {
        Sampler {
            key: hash_extend(pixel_key, index),
            dim: 0,
        }
    }

    /// The sampler with key `key` whose next dimension is `dim` (drawn by lanes before).
    pub(crate) fn from_state(key: u64, dim: u64) -> Sampler {
        Sampler { key, dim }
    }

    /// The next dimension's value in `[0, 1)`.
    pub fn next_1d(&mut self) -> f32 {
        let h = prism_math::mix64(self.key ^ self.dim.wrapping_mul(DIM_MUL));
        self.dim += 1;
        unit_f32((h >> 32) as u32)
    }

    /// The key and the next dimension, for drawing by lanes ([`lane_values`]).
    pub(crate) fn state(&self) -> (u64, u64) {
        (self.key, self.dim)
    }

    /// Skips `n` dimensions (drawn by lanes).
    pub(crate) fn advance(&mut self, n: u64) {
        self.dim += n;
    }

    /// The next two dimensions.
    pub fn next_2d(&mut self) -> Vec2 {
        Vec2::new(self.next_1d(), self.next_1d())
    }
}

/// The multiplier that spreads dimensions before mixing.
const DIM_MUL: u64 = 0x9e37_79b9_7f4a_7c15;

/// The keys of sixteen pixels' samplers of sample `index` ([`Sampler::from_pixel_key`] on
/// lanes, bit for bit).
#[inline(always)]
#[allow(clippy::needless_range_loop)]
pub(crate) fn lane_keys(pixel_keys: &[u64; LANES], index: u64) -> [u64; LANES] {
    let w = word_mix(index);
    let mut z = [0u64; LANES];
    for i in 0..LANES {
        z[i] = pixel_keys[i] ^ w;
    }
    mix_lanes(z)
}

/// `prism_math::mix64` of each lane, in its operations.
#[inline(always)]
#[allow(clippy::needless_range_loop)]
fn mix_lanes(mut z: [u64; LANES]) -> [u64; LANES] {
    for i in 0..LANES {
        z[i] = (z[i] ^ (z[i] >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    }
    for i in 0..LANES {
        z[i] = (z[i] ^ (z[i] >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    }
    for i in 0..LANES {
        z[i] ^= z[i] >> 31;
    }
    z
}

/// For sixteen samplers at once (keys `key`, next dimensions `dim`): the value each draws
/// `j` dimensions later, the value [`Sampler::next_1d`] gives, bit for bit.
#[inline(always)]
#[allow(clippy::needless_range_loop)]
pub(crate) fn lane_values(key: &[u64; LANES], dim: &[u64; LANES], j: u64) -> F16 {
    let mut z = [0u64; LANES];
    for i in 0..LANES {
        z[i] = key[i] ^ dim[i].wrapping_add(j).wrapping_mul(DIM_MUL);
    }
    let z = mix_lanes(z);
    let mut r = [0.0; LANES];
    for i in 0..LANES {
        // The top 24 bits, as `unit_f32` takes them; exact in i32 and in f32.
        r[i] = ((z[i] >> 40) as i32) as f32 * (1.0 / 16_777_216.0);
    }
    F16(r)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Property: samplers started from a pixel key, alone or on lanes, are
    /// `Sampler::new`'s (the same key, hence the same values).
    #[test]
    fn pixel_keys_give_the_samplers_of_new() {
        let pixels: [u64; LANES] = std::array::from_fn(|i| i as u64 * 7919 + 3);
        let keys = pixels.map(|p| Sampler::pixel_key(11, p));
        for index in [0u64, 1, 63, 1 << 40] {
            let lanes = lane_keys(&keys, index);
            for i in 0..LANES {
                let mut a = Sampler::new(11, pixels[i], index);
                let mut b = Sampler::from_pixel_key(keys[i], index);
                assert_eq!(a.state(), b.state());
                assert_eq!(lanes[i], a.state().0, "lane {i}, sample {index}");
                assert_eq!(a.next_1d().to_bits(), b.next_1d().to_bits());
            }
        }
    }

    /// Property: drawing by lanes gives `next_1d`'s values bit for bit.
    #[test]
    fn lane_values_equal_next_1d() {
        let mut samplers: Vec<Sampler> = (0..LANES as u64)
            .map(|i| {
                let mut s = Sampler::new(7, i * 977, i);
                s.advance(i % 5);
                s
            })
            .collect();
        let key = std::array::from_fn(|i| samplers[i].state().0);
        let dim = std::array::from_fn(|i| samplers[i].state().1);
        for j in 0..9 {
            let lanes = lane_values(&key, &dim, j);
            for (i, s) in samplers.iter_mut().enumerate() {
                assert_eq!(
                    lanes.0[i].to_bits(),
                    s.next_1d().to_bits(),
                    "lane {i}, draw {j}"
                );
            }
        }
    }
}
