//! [`Isa`], the instruction sets the SIMD kernels may use: what the processor has, capped by
//! the `PRISM_ISA` environment variable (`avx512`, `avx2`, `avx` or `sse`), so that a run
//! can take the code paths of an older processor. Every kernel computes the same operations
//! in the same order whatever it runs on, so the cap changes speed, never results.

use std::sync::OnceLock;

/// The instruction-set levels the kernels are compiled for, lowest first.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Isa {
    /// SSE2 only (every x86-64 processor), or a processor other than x86-64.
    Sse,
    /// AVX (256-bit floating-point vectors).
    Avx,
    /// AVX2 (256-bit integer vectors and gathers) and FMA.
    Avx2,
    /// AVX-512 F, DQ and VL.
    Avx512,
}

impl Isa {
    /// The level kernels may use: the processor's, capped by `PRISM_ISA` if set to a known
    /// name (an unknown name caps nothing). Detected once per process.
    #[must_use]
    pub fn get() -> Isa {
        static LEVEL: OnceLock<Isa> = OnceLock::new();
        *LEVEL.get_or_init(|| {
            let cap = std::env::var("PRISM_ISA")
                .ok()
                .and_then(|s| Isa::parse(&s))
                .unwrap_or(Isa::Avx512);
            Isa::detect().min(cap)
        })
    }

    /// True if kernels may use AVX-512 (F, DQ and VL).
    #[must_use]
    pub fn avx512() -> bool {
        Isa::get() >= Isa::Avx512
    }

    /// True if kernels may use AVX2.
    #[must_use]
    pub fn avx2() -> bool {
        Isa::get() >= Isa::Avx2
    }

    /// True if kernels may use AVX.
    #[must_use]
    pub fn avx() -> bool {
        Isa::get() >= Isa::Avx
    }

    /// The level's name, as `PRISM_ISA` takes it.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Isa::Sse => "sse",
            Isa::Avx => "avx",
            Isa::Avx2 => "avx2",
            Isa::Avx512 => "avx512",
        }
    }

    /// The level a name stands for (`avx512`, `avx2`, `avx`, `sse`; any case).
    #[must_use]
    pub fn parse(name: &str) -> Option<Isa> {
        match name.trim().to_ascii_lowercase().as_str() {
            "avx512" => Some(Isa::Avx512),
            "avx2" => Some(Isa::Avx2),
            "avx" => Some(Isa::Avx),
            "sse" | "sse2" => Some(Isa::Sse),
            _ => None,
        }
    }

    /// The highest level the processor has.
    fn detect() -> Isa {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::is_x86_feature_detected as has;
            if has!("avx512f") && has!("avx512dq") && has!("avx512vl") {
                return Isa::Avx512;
            }
            if has!("avx2") && has!("fma") {
                return Isa::Avx2;
            }
            if has!("avx") {
                return Isa::Avx;
            }
        }
        Isa::Sse
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Property: names parse to their levels, in any case, and the levels are ordered.
    #[test]
    fn names_parse_and_levels_order() {
        assert_eq!(Isa::parse("AVX512"), Some(Isa::Avx512));
        assert_eq!(Isa::parse(" avx2 "), Some(Isa::Avx2));
        assert_eq!(Isa::parse("avx"), Some(Isa::Avx));
        assert_eq!(Isa::parse("sse2"), Some(Isa::Sse));
        assert_eq!(Isa::parse("neon"), None);
        for isa in [Isa::Sse, Isa::Avx, Isa::Avx2, Isa::Avx512] {
            assert_eq!(Isa::parse(isa.name()), Some(isa));
        }
        assert!(Isa::Sse < Isa::Avx && Isa::Avx < Isa::Avx2 && Isa::Avx2 < Isa::Avx512);
        // Whatever the cap, the level never exceeds what the processor has.
        assert!(Isa::get() <= Isa::detect());
    }
}
