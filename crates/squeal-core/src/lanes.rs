//! One number per lane of an ensemble: [`Lanes`], [`LANES`] `f64` held
//! as `W` vectors of four (`wide`'s [`f64x4`]: one AVX2 register each on
//! the x86-64-v3 build).
//!
//! Every operation is the lane-wise IEEE operation of [`f64x4`], so each
//! lane's number is bit for bit the scalar one. `wide` has no eight-wide
//! `f64` type, and this wrapper is all that the ensemble needs of one (a
//! handful of operators, masks and blends), so the width is one constant.
//!
//! `W = 1` (four lanes) is measured to be the best choice for squeal's
//! ensembles (BENCHMARKS.md, issue 16). Two vectors (eight lanes) give the
//! processor two independent chains of the lane-wise right-hand side, whose
//! latency sets its pace: on 16 event-free runs (`speed_probe lanes 4f`)
//! they take 0.36 s against 0.40 – 0.42 s. But a transient map's lanes idle
//! more often at the end of a task (77 % of lane slots busy against 90 %),
//! which cancels the gain there, and `reproduce` gives an ensemble at most
//! four runs. Four vectors (16 lanes) spill registers and are slower.

use std::ops::{Add, AddAssign, BitAnd, Div, Mul, Neg, Sub};
use wide::{f64x4, CmpEq, CmpGt, CmpLt};

/// Vectors of four per [`Lanes`] (see the module's note on the choice).
const W: usize = 1;

/// Lanes of an ensemble: one [`Lanes`] holds a number of each.
pub const LANES: usize = 4 * W;

/// [`LANES`] numbers, one per lane, operated on lane by lane.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lanes([f64x4; W]);

impl Lanes {
    /// Zero in every lane.
    pub const ZERO: Lanes = Lanes([f64x4::ZERO; W]);
    /// One in every lane.
    pub const ONE: Lanes = Lanes([f64x4::ONE; W]);

    /// `x` in every lane.
    #[inline(always)]
    pub fn splat(x: f64) -> Lanes {
        Lanes([f64x4::splat(x); W])
    }

    /// The lanes' numbers, lane `l` from `a[l]`.
    #[inline(always)]
    pub fn new(a: [f64; LANES]) -> Lanes {
        Lanes(std::array::from_fn(|w| {
            f64x4::new([a[4 * w], a[4 * w + 1], a[4 * w + 2], a[4 * w + 3]])
        }))
    }

    /// The mask (all bits set) of the lanes in `set`, for [`Self::blend`].
    #[inline(always)]
    pub fn mask(set: [bool; LANES]) -> Lanes {
        Lanes::new(set.map(|b| if b { 1.0 } else { 0.0 })).cmp_gt(Lanes::ZERO)
    }

    /// Every lane's number.
    #[inline(always)]
    pub fn to_array(self) -> [f64; LANES] {
        std::array::from_fn(|l| self.lane(l))
    }

    /// Lane `l`'s number.
    #[inline(always)]
    pub fn lane(&self, l: usize) -> f64 {
        self.0[l / 4].as_array_ref()[l % 4]
    }

    #[inline(always)]
    fn map(self, f: impl Fn(f64x4) -> f64x4) -> Lanes {
        Lanes(std::array::from_fn(|w| f(self.0[w])))
    }

    #[inline(always)]
    fn zip(self, o: Lanes, f: impl Fn(f64x4, f64x4) -> f64x4) -> Lanes {
        Lanes(std::array::from_fn(|w| f(self.0[w], o.0[w])))
    }

    /// `|x|` lane by lane.
    #[inline(always)]
    pub fn abs(self) -> Lanes {
        self.map(f64x4::abs)
    }

    /// The larger number lane by lane ([`f64x4::max`]: where one is NaN,
    /// the other, as `f64::max`).
    #[inline(always)]
    pub fn max(self, o: Lanes) -> Lanes {
        self.zip(o, f64x4::max)
    }

    /// `√x` lane by lane (correctly rounded, as `f64::sqrt`).
    #[inline(always)]
    pub fn sqrt(self) -> Lanes {
        self.map(f64x4::sqrt)
    }

    /// Mask (all bits set) where `self == o`.
    #[inline(always)]
    pub fn cmp_eq(self, o: Lanes) -> Lanes {
        self.zip(o, |a, b| a.cmp_eq(b))
    }

    /// Mask where `self > o`.
    #[inline(always)]
    pub fn cmp_gt(self, o: Lanes) -> Lanes {
        self.zip(o, |a, b| a.cmp_gt(b))
    }

    /// Mask where `self < o`.
    #[inline(always)]
    pub fn cmp_lt(self, o: Lanes) -> Lanes {
        self.zip(o, |a, b| a.cmp_lt(b))
    }

    /// With `self` a mask: `t` where it is set, `f` elsewhere.
    #[inline(always)]
    pub fn blend(self, t: Lanes, f: Lanes) -> Lanes {
        Lanes(std::array::from_fn(|w| self.0[w].blend(t.0[w], f.0[w])))
    }

    /// With `self` a mask: whether any lane is set.
    #[inline(always)]
    pub fn any(self) -> bool {
        self.0.iter().any(|v| v.any())
    }
}

macro_rules! lane_op {
    ($tr:ident, $f:ident) => {
        impl $tr for Lanes {
            type Output = Lanes;
            #[inline(always)]
            fn $f(self, o: Lanes) -> Lanes {
                self.zip(o, |a, b| a.$f(b))
            }
        }
    };
}
lane_op!(Add, add);
lane_op!(Sub, sub);
lane_op!(Mul, mul);
lane_op!(Div, div);
lane_op!(BitAnd, bitand);

impl Neg for Lanes {
    type Output = Lanes;
    #[inline(always)]
    fn neg(self) -> Lanes {
        self.map(|a| -a)
    }
}

impl AddAssign for Lanes {
    #[inline(always)]
    fn add_assign(&mut self, o: Lanes) {
        *self = *self + o;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lanes_are_the_scalar_operations() {
        let a: [f64; LANES] = std::array::from_fn(|l| 1.0 / (l as f64 + 0.3) - 0.9);
        let b: [f64; LANES] = std::array::from_fn(|l| (l as f64 * 0.7).sin());
        let (va, vb) = (Lanes::new(a), Lanes::new(b));
        for l in 0..LANES {
            let (x, y) = (a[l], b[l]);
            assert_eq!((va + vb).lane(l).to_bits(), (x + y).to_bits());
            assert_eq!((va - vb).lane(l).to_bits(), (x - y).to_bits());
            assert_eq!((va * vb).lane(l).to_bits(), (x * y).to_bits());
            assert_eq!((va / vb).lane(l).to_bits(), (x / y).to_bits());
            assert_eq!((-va).lane(l).to_bits(), (-x).to_bits());
            assert_eq!(va.abs().sqrt().lane(l).to_bits(), x.abs().sqrt().to_bits());
            assert_eq!(va.max(vb).lane(l), x.max(y));
            let pick = va.cmp_lt(vb).blend(va, vb).lane(l);
            assert_eq!(pick, if x < y { x } else { y });
        }
        assert_eq!(Lanes::new(a).to_array(), a);
        let set: [bool; LANES] = std::array::from_fn(|l| l % 3 == 1);
        let picked = Lanes::mask(set).blend(va, vb).to_array();
        assert_eq!(
            picked,
            std::array::from_fn(|l| if set[l] { a[l] } else { b[l] })
        );
        assert!(!Lanes::mask([false; LANES]).any());
        assert!(va.cmp_gt(Lanes::ZERO).any());
        assert!(!va.cmp_gt(Lanes::splat(10.0)).any());
        let nan = Lanes::splat(f64::NAN).max(Lanes::ONE);
        assert_eq!(nan.to_array(), [1.0; LANES]);
    }
}
