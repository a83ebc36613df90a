//! The only code of this crate that touches `std::arch`: the instruction sets the SIMD
//! kernels may use ([`Isa`], in `isa`) and a cache prefetch hint ([`prefetch`], in
//! `prefetch`).

mod isa;
mod prefetch;

pub use isa::Isa;
pub use prefetch::prefetch;
