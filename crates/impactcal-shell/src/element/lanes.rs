//! Lane values: the arithmetic the element pieces are written on, one value per element.
//!
//! [`Lane`] is implemented by `f64` (one element: the triangle, one lane) and by [`V`], a
//! short vector of [`LANES`] values (a block of quads, structure of arrays), so that the
//! compiler can issue packed instructions across the elements of a block. Every lane is
//! computed independently with plain IEEE operations (no fused multiply-add), so an
//! element's result does not depend on the block it sits in, the lane it occupies or the
//! number of threads.

use std::ops::{Add, AddAssign, Div, Mul, Neg, Sub, SubAssign};

/// Elements per block of the quad path.
pub(crate) const LANES: usize = 2;

/// One value per element of a group evaluated together. Operations act lane by lane; the
/// `f64` operand of the mixed operations is applied to every lane.
pub(crate) trait Lane:
    Copy
    + Default
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + AddAssign
    + SubAssign
    + Add<f64, Output = Self>
    + Sub<f64, Output = Self>
    + Mul<f64, Output = Self>
    + Div<f64, Output = Self>
{
    /// The number of lanes.
    const WIDTH: usize;
    /// Every lane equal to `a`.
    fn splat(a: f64) -> Self;
    /// Lane `l`.
    fn lane(self, l: usize) -> f64;
    /// Sets lane `l`.
    fn set_lane(&mut self, l: usize, a: f64);
    /// `f` applied to every lane.
    fn map(self, f: impl Fn(f64) -> f64) -> Self;
}

impl Lane for f64 {
    const WIDTH: usize = 1;
    #[inline(always)]
    fn splat(a: f64) -> f64 {
        a
    }
    #[inline(always)]
    fn lane(self, _: usize) -> f64 {
        self
    }
    #[inline(always)]
    fn set_lane(&mut self, _: usize, a: f64) {
        *self = a;
    }
    #[inline(always)]
    fn map(self, f: impl Fn(f64) -> f64) -> f64 {
        f(self)
    }
}

/// [`LANES`] values, one per element of a block of quads.
#[derive(Debug, Clone, Copy, Default)]
#[repr(align(16))]
pub(crate) struct V(pub [f64; LANES]);

impl V {
    #[inline(always)]
    fn zip(self, o: V, f: impl Fn(f64, f64) -> f64) -> V {
        let mut r = [0.0; LANES];
        for l in 0..LANES {
            r[l] = f(self.0[l], o.0[l]);
        }
        V(r)
    }

    /// The lane-wise square root.
    #[inline(always)]
    pub(crate) fn sqrt(self) -> V {
        self.map(f64::sqrt)
    }

    /// The lane-wise maximum (the first operand where they compare equal).
    #[inline(always)]
    pub(crate) fn max(self, o: V) -> V {
        self.zip(o, |a, b| if a >= b { a } else { b })
    }
}

impl Lane for V {
    const WIDTH: usize = LANES;
    #[inline(always)]
    fn splat(a: f64) -> V {
        V([a; LANES])
    }
    #[inline(always)]
    fn lane(self, l: usize) -> f64 {
        self.0[l]
    }
    #[inline(always)]
    fn set_lane(&mut self, l: usize, a: f64) {
        self.0[l] = a;
    }
    #[inline(always)]
    fn map(self, f: impl Fn(f64) -> f64) -> V {
        V(self.0.map(f))
    }
}

macro_rules! binop {
    ($tr:ident, $f:ident, $op:tt) => {
        impl $tr for V {
            type Output = V;
            #[inline(always)]
            fn $f(self, o: V) -> V {
                self.zip(o, |a, b| a $op b)
            }
        }
        impl $tr<f64> for V {
            type Output = V;
            #[inline(always)]
            fn $f(self, o: f64) -> V {
                self.map(|a| a $op o)
            }
        }
        impl $tr<V> for f64 {
            type Output = V;
            #[inline(always)]
            fn $f(self, o: V) -> V {
                o.map(|b| self $op b)
            }
        }
    };
}
binop!(Add, add, +);
binop!(Sub, sub, -);
binop!(Mul, mul, *);
binop!(Div, div, /);

impl Neg for V {
    type Output = V;
    #[inline(always)]
    fn neg(self) -> V {
        self.map(|a| -a)
    }
}

impl AddAssign for V {
    #[inline(always)]
    fn add_assign(&mut self, o: V) {
        *self = *self + o;
    }
}

impl SubAssign for V {
    #[inline(always)]
    fn sub_assign(&mut self, o: V) {
        *self = *self - o;
    }
}

/// A 3-vector of lane values.
pub(crate) type L3<L> = [L; 3];

/// `a - b`.
#[inline(always)]
pub(crate) fn sub3<L: Lane>(a: L3<L>, b: L3<L>) -> L3<L> {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// `a . b`.
#[inline(always)]
pub(crate) fn dot3<L: Lane>(a: L3<L>, b: L3<L>) -> L {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `a x b`.
#[inline(always)]
pub(crate) fn cross3<L: Lane>(a: L3<L>, b: L3<L>) -> L3<L> {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
