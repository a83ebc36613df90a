//! [`GlibcRand`], the C library's `rand()` as glibc computes it (the additive feedback
//! generator behind `random()`), from a seed: the course app never seeds it, so its
//! numbers are those of seed 1.

/// glibc's `rand()`: `RAND_MAX` is 2147483647.
#[derive(Clone, Debug)]
pub struct GlibcRand {
    r: Vec<u32>,
}

/// `RAND_MAX`.
pub const RAND_MAX: u32 = 2_147_483_647;

impl GlibcRand {
    /// The generator after `srand(seed)`.
    #[must_use]
    pub fn new(seed: u32) -> GlibcRand {
        let mut r = vec![0u32; 34];
        r[0] = seed;
        for i in 1..31 {
            // 16807 r mod (2^31 - 1), in signed 32-bit arithmetic as glibc does it.
            let prev = i64::from(r[i - 1] as i32);
            let hi = prev / 127_773;
            let lo = prev % 127_773;
            let mut word = 16_807 * lo - 2_836 * hi;
            if word < 0 {
                word += 2_147_483_647;
            }
            r[i] = word as u32;
        }
        for i in 31..34 {
            r[i] = r[i - 31];
        }
        let mut g = GlibcRand { r };
        // The first 310 outputs are discarded.
        for _ in 34..344 {
            g.advance();
        }
        g
    }

    fn advance(&mut self) -> u32 {
        let n = self.r.len();
        let v = self.r[n - 31].wrapping_add(self.r[n - 3]);
        self.r.push(v);
        if self.r.len() > 4096 {
            self.r.drain(..self.r.len() - 34);
        }
        v
    }

    /// The next `rand()`.
    pub fn rand(&mut self) -> u32 {
        self.advance() >> 1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// glibc's documented sequence for the unseeded generator.
    #[test]
    fn first_outputs_of_seed_one() {
        let mut g = GlibcRand::new(1);
        let first: Vec<u32> = (0..5).map(|_| g.rand()).collect();
        assert_eq!(
            first,
            [1804289383, 846930886, 1681692777, 1714636915, 1957747793]
        );
        for _ in 0..10_000 {
            assert!(g.rand() <= RAND_MAX);
        }
    }
}
