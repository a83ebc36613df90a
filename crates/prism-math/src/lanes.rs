//! [`F16`], [`M16`] and [`V16`]: sixteen samples side by side (numbers, masks, vectors), with
//! each operation the scalar one lane by lane, so that results equal the scalar code's bit
//! for bit; compiled for AVX-512 they become single vector instructions (two with AVX2).

// Plain index loops over the lanes are what the vectoriser turns into single instructions.
#![allow(clippy::needless_range_loop)]

use std::ops::{Add, BitAnd, BitOr, BitXor, Div, Mul, Neg, Not, Sub};

use glam::Vec3;

/// Lanes per group.
pub const LANES: usize = 16;

/// Sixteen `f32`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct F16(pub [f32; LANES]);

/// Sixteen lane conditions: all ones where true.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct M16(pub [i32; LANES]);

/// Sixteen 3-vectors, one [`F16`] per axis.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct V16 {
    /// x coordinates.
    pub x: F16,
    /// y coordinates.
    pub y: F16,
    /// z coordinates.
    pub z: F16,
}

macro_rules! lanewise {
    ($trait:ident, $f:ident, $op:tt) => {
        impl $trait for F16 {
            type Output = F16;
            #[inline(always)]
            fn $f(self, o: F16) -> F16 {
                let mut r = [0.0; LANES];
                for i in 0..LANES {
                    r[i] = self.0[i] $op o.0[i];
                }
                F16(r)
            }
        }
        impl $trait<f32> for F16 {
            type Output = F16;
            #[inline(always)]
            fn $f(self, o: f32) -> F16 {
                let mut r = [0.0; LANES];
                for i in 0..LANES {
                    r[i] = self.0[i] $op o;
                }
                F16(r)
            }
        }
    };
}
lanewise!(Add, add, +);
lanewise!(Sub, sub, -);
lanewise!(Mul, mul, *);
lanewise!(Div, div, /);

impl F16 {
    /// Every lane `v`.
    #[inline(always)]
    pub fn splat(v: f32) -> F16 {
        F16([v; LANES])
    }

    /// The first sixteen values of `s`.
    #[inline(always)]
    pub fn load(s: &[f32]) -> F16 {
        let mut r = [0.0; LANES];
        r.copy_from_slice(&s[..LANES]);
        F16(r)
    }

    /// Writes the lanes to the first sixteen values of `s`.
    #[inline(always)]
    pub fn store(self, s: &mut [f32]) {
        s[..LANES].copy_from_slice(&self.0);
    }

    /// Square roots.
    #[inline(always)]
    pub fn sqrt(self) -> F16 {
        let mut r = [0.0; LANES];
        for i in 0..LANES {
            r[i] = self.0[i].sqrt();
        }
        F16(r)
    }

    /// `max(v, 0)`, 0 for NaN (as `f32::max(v, 0.0)`; the sign of a zero may differ).
    #[inline(always)]
    pub fn max0(self) -> F16 {
        let mut r = [0.0; LANES];
        for i in 0..LANES {
            r[i] = if self.0[i] > 0.0 { self.0[i] } else { 0.0 };
        }
        F16(r)
    }

    /// `self < o`.
    #[inline(always)]
    pub fn lt(self, o: F16) -> M16 {
        let mut r = [0; LANES];
        for i in 0..LANES {
            r[i] = -i32::from(self.0[i] < o.0[i]);
        }
        M16(r)
    }

    /// `self > o`.
    #[inline(always)]
    pub fn gt(self, o: F16) -> M16 {
        o.lt(self)
    }

    /// `self <= o`.
    #[inline(always)]
    pub fn le(self, o: F16) -> M16 {
        let mut r = [0; LANES];
        for i in 0..LANES {
            r[i] = -i32::from(self.0[i] <= o.0[i]);
        }
        M16(r)
    }

    /// `self != o` (true for NaN lanes).
    #[inline(always)]
    pub fn ne(self, o: F16) -> M16 {
        !self.eq(o)
    }

    /// The larger of the two ignoring NaN, as `f32::max`.
    #[inline(always)]
    pub fn max_num(self, o: F16) -> F16 {
        let mut r = [0.0; LANES];
        for i in 0..LANES {
            let (a, b) = (self.0[i], o.0[i]);
            r[i] = if a > b || b.is_nan() { a } else { b };
        }
        F16(r)
    }

    /// The smaller of the two ignoring NaN, as `f32::min`.
    #[inline(always)]
    pub fn min_num(self, o: F16) -> F16 {
        let mut r = [0.0; LANES];
        for i in 0..LANES {
            let (a, b) = (self.0[i], o.0[i]);
            r[i] = if a < b || b.is_nan() { a } else { b };
        }
        F16(r)
    }

    /// `f` of each lane, as a loop over the lanes (which the vectoriser turns into lane
    /// operations once `f` is inlined).
    #[inline(always)]
    fn each(self, f: impl Fn(f32) -> f32) -> F16 {
        let mut r = [0.0; LANES];
        for i in 0..LANES {
            r[i] = f(self.0[i]);
        }
        F16(r)
    }

    /// [`crate::exp`] of each lane.
    #[inline(always)]
    pub fn exp(self) -> F16 {
        self.each(crate::exp)
    }

    /// [`crate::ln`] of each lane.
    #[inline(always)]
    pub fn ln(self) -> F16 {
        self.each(crate::ln)
    }

    /// [`crate::acos`] of each lane.
    #[inline(always)]
    pub fn acos(self) -> F16 {
        self.each(crate::acos)
    }

    /// Absolute values.
    #[inline(always)]
    pub fn abs(self) -> F16 {
        let mut r = [0.0; LANES];
        for i in 0..LANES {
            r[i] = self.0[i].abs();
        }
        F16(r)
    }

    /// The magnitudes of `self` with the signs of `sign`, as `f32::copysign`.
    #[inline(always)]
    pub fn copysign(self, sign: F16) -> F16 {
        let mut r = [0.0; LANES];
        for i in 0..LANES {
            r[i] = self.0[i].copysign(sign.0[i]);
        }
        F16(r)
    }

    /// Lanes that are neither infinite nor NaN.
    #[inline(always)]
    pub fn is_finite(self) -> M16 {
        let mut r = [0; LANES];
        for i in 0..LANES {
            r[i] = -i32::from(self.0[i].is_finite());
        }
        M16(r)
    }

    /// `self == o`.
    #[inline(always)]
    pub fn eq(self, o: F16) -> M16 {
        let mut r = [0; LANES];
        for i in 0..LANES {
            r[i] = -i32::from(self.0[i] == o.0[i]);
        }
        M16(r)
    }

    /// `a` where `m`, else `b`.
    #[inline(always)]
    pub fn select(m: M16, a: F16, b: F16) -> F16 {
        let mut r = [0.0; LANES];
        for i in 0..LANES {
            r[i] = if m.0[i] != 0 { a.0[i] } else { b.0[i] };
        }
        F16(r)
    }
}

impl M16 {
    /// Every lane `v`.
    #[inline(always)]
    pub fn splat(v: bool) -> M16 {
        M16([-i32::from(v); LANES])
    }

    /// Lanes `i < n`.
    #[inline(always)]
    pub fn first(n: usize) -> M16 {
        let mut r = [0; LANES];
        for (i, m) in r.iter_mut().enumerate() {
            *m = -i32::from(i < n);
        }
        M16(r)
    }

    /// True if any lane is.
    #[inline(always)]
    pub fn any(self) -> bool {
        self.0.iter().fold(0, |a, &m| a | m) != 0
    }

    /// Lane `i`.
    #[inline(always)]
    pub fn get(self, i: usize) -> bool {
        self.0[i] != 0
    }

    /// Bit `i` set where lane `i` is true.
    #[inline(always)]
    pub fn bits(self) -> u32 {
        let mut b = 0;
        for i in 0..LANES {
            b |= u32::from(self.0[i] != 0) << i;
        }
        b
    }

    /// Lane `i` true where bit `i` of `bits` is set.
    #[inline(always)]
    pub fn from_bits(bits: u32) -> M16 {
        let mut r = [0; LANES];
        for i in 0..LANES {
            r[i] = -(((bits >> i) & 1) as i32);
        }
        M16(r)
    }
}

impl BitAnd for M16 {
    type Output = M16;
    #[inline(always)]
    fn bitand(self, o: M16) -> M16 {
        let mut r = [0; LANES];
        for i in 0..LANES {
            r[i] = self.0[i] & o.0[i];
        }
        M16(r)
    }
}

impl BitOr for M16 {
    type Output = M16;
    #[inline(always)]
    fn bitor(self, o: M16) -> M16 {
        let mut r = [0; LANES];
        for i in 0..LANES {
            r[i] = self.0[i] | o.0[i];
        }
        M16(r)
    }
}

impl BitXor for M16 {
    type Output = M16;
    #[inline(always)]
    fn bitxor(self, o: M16) -> M16 {
        let mut r = [0; LANES];
        for i in 0..LANES {
            r[i] = self.0[i] ^ o.0[i];
        }
        M16(r)
    }
}

impl Not for M16 {
    type Output = M16;
    #[inline(always)]
    fn not(self) -> M16 {
        let mut r = [0; LANES];
        for i in 0..LANES {
            r[i] = !self.0[i];
        }
        M16(r)
    }
}

impl Neg for F16 {
    type Output = F16;
    #[inline(always)]
    fn neg(self) -> F16 {
        let mut r = [0.0; LANES];
        for i in 0..LANES {
            r[i] = -self.0[i];
        }
        F16(r)
    }
}

impl Neg for V16 {
    type Output = V16;
    #[inline(always)]
    fn neg(self) -> V16 {
        V16 {
            x: -self.x,
            y: -self.y,
            z: -self.z,
        }
    }
}

impl V16 {
    /// Every lane `v`.
    #[inline(always)]
    pub fn splat(v: Vec3) -> V16 {
        V16 {
            x: F16::splat(v.x),
            y: F16::splat(v.y),
            z: F16::splat(v.z),
        }
    }

    /// `x x' + y y' + z z'`, in glam's order.
    #[inline(always)]
    pub fn dot(self, o: V16) -> F16 {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    /// `self * (1 / |self|)`, as glam's `normalize`.
    #[inline(always)]
    pub fn normalize(self) -> V16 {
        let r = F16::splat(1.0) / self.dot(self).sqrt();
        self * r
    }
}

impl Add for V16 {
    type Output = V16;
    #[inline(always)]
    fn add(self, o: V16) -> V16 {
        V16 {
            x: self.x + o.x,
            y: self.y + o.y,
            z: self.z + o.z,
        }
    }
}

impl Sub for V16 {
    type Output = V16;
    #[inline(always)]
    fn sub(self, o: V16) -> V16 {
        V16 {
            x: self.x - o.x,
            y: self.y - o.y,
            z: self.z - o.z,
        }
    }
}

impl Mul<F16> for V16 {
    type Output = V16;
    #[inline(always)]
    fn mul(self, s: F16) -> V16 {
        V16 {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Property: every lane operation equals glam's scalar one bit for bit.
    #[test]
    fn lanes_equal_scalar_glam() {
        let v: Vec<Vec3> = (0..LANES)
            .map(|i| {
                let t = i as f32 * 0.37 + 0.11;
                Vec3::new(t.sin() * 3.1, (t * 1.7).cos() - 0.2, t * t - 1.3)
            })
            .collect();
        let lanes = V16 {
            x: F16(std::array::from_fn(|i| v[i].x)),
            y: F16(std::array::from_fn(|i| v[i].y)),
            z: F16(std::array::from_fn(|i| v[i].z)),
        };
        let n = lanes.normalize();
        let d = lanes.dot(V16::splat(Vec3::new(0.3, -0.8, 0.1)));
        for i in 0..LANES {
            let s = v[i].normalize();
            assert_eq!([n.x.0[i], n.y.0[i], n.z.0[i]], s.to_array());
            assert_eq!(d.0[i], v[i].dot(Vec3::new(0.3, -0.8, 0.1)));
            assert_eq!(d.max0().0[i], d.0[i].max(0.0) + 0.0);
        }
        assert_eq!(F16::splat(f32::NAN).max0(), F16::splat(0.0));
        assert!(M16::first(3).get(2) && !M16::first(3).get(3));
    }

    /// Property: comparisons, `f32::max`/`min` (NaN ignored), `abs`, `copysign`, negation,
    /// finiteness and mask bits equal the scalar operations lane by lane, NaN, infinities and
    /// signed zeros included.
    #[test]
    fn lane_operations_equal_scalar() {
        let specials = [
            0.0,
            -0.0,
            1.5,
            -2.25,
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            3e-39,
        ];
        let a = F16(std::array::from_fn(|i| specials[i % 8]));
        let b = F16(std::array::from_fn(|i| specials[(i * 3 + 1) % 8]));
        for i in 0..LANES {
            let (x, y) = (a.0[i], b.0[i]);
            assert_eq!(a.lt(b).get(i), x < y);
            assert_eq!(a.gt(b).get(i), x > y);
            assert_eq!(a.le(b).get(i), x <= y);
            assert_eq!(a.ne(b).get(i), x != y);
            assert_eq!(a.is_finite().get(i), x.is_finite());
            let (mx, mn) = (a.max_num(b).0[i], a.min_num(b).0[i]);
            assert!(
                mx == x.max(y) || (mx.is_nan() && x.max(y).is_nan()),
                "{x} {y}"
            );
            assert!(
                mn == x.min(y) || (mn.is_nan() && x.min(y).is_nan()),
                "{x} {y}"
            );
            assert_eq!(a.abs().0[i].to_bits(), x.abs().to_bits());
            assert_eq!(a.copysign(b).0[i].to_bits(), x.copysign(y).to_bits());
            assert_eq!((-a).0[i].to_bits(), (-x).to_bits());
        }
        let m = a.lt(b);
        assert_eq!(M16::from_bits(m.bits()), m);
        assert_eq!((m ^ M16::splat(true)), !m);
    }
}
