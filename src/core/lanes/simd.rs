//! Arithmetic on `L` lanes at once: one lane per chain of a lane group.
//!
//! Every operation is an element-wise loop over a plain array, written so the compiler's vectoriser turns it
//! into whatever SIMD instructions the function it is inlined into may use (SSE2 in the portable build, AVX2
//! in the copy [`multiversion`] compiles for CPUs that have it). Nothing here fuses or reorders
//! floating-point operations, so a lane computes exactly the same bits whatever `L`, whatever its
//! neighbours, and whatever instruction set ran it: that is the lane path's determinism policy.
//!
//! The vector and quaternion formulas follow glam's scalar implementations.

use std::ops::{Add, Div, Mul, Neg, Sub};

/// `L` single-precision lanes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct F<const L: usize>(pub [f32; L]);

/// `L` double-precision lanes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct D<const L: usize>(pub [f64; L]);

/// A per-lane condition.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mask<const L: usize>(pub [bool; L]);

macro_rules! lanewise {
    ($ty:ident, $elem:ty, $bits:ty) => {
        // The same set for both lane types; not every operation is used on both.
        #[allow(dead_code)]
        impl<const L: usize> $ty<L> {
            #[inline(always)]
            pub fn splat(x: $elem) -> Self {
                Self([x; L])
            }

            #[inline(always)]
            pub fn map(self, f: impl Fn($elem) -> $elem) -> Self {
                let mut r = self.0;
                for i in 0..L {
                    r[i] = f(self.0[i]);
                }
                Self(r)
            }

            #[inline(always)]
            pub fn zip(self, o: Self, f: impl Fn($elem, $elem) -> $elem) -> Self {
                let mut r = self.0;
                for i in 0..L {
                    r[i] = f(self.0[i], o.0[i]);
                }
                Self(r)
            }

            #[inline(always)]
            pub fn abs(self) -> Self {
                self.map(<$elem>::abs)
            }

            #[inline(always)]
            pub fn sqrt(self) -> Self {
                self.map(<$elem>::sqrt)
            }

            #[inline(always)]
            pub fn gt(self, o: Self) -> Mask<L> {
                let mut r = [false; L];
                for i in 0..L {
                    r[i] = self.0[i] > o.0[i];
                }
                Mask(r)
            }

            #[inline(always)]
            pub fn lt(self, o: Self) -> Mask<L> {
                o.gt(self)
            }

            #[inline(always)]
            pub fn le(self, o: Self) -> Mask<L> {
                let mut r = [false; L];
                for i in 0..L {
                    r[i] = self.0[i] <= o.0[i];
                }
                Mask(r)
            }

            #[inline(always)]
            pub fn ge(self, o: Self) -> Mask<L> {
                o.le(self)
            }

            #[inline(always)]
            pub fn is_finite(self) -> Mask<L> {
                let mut r = [false; L];
                for i in 0..L {
                    r[i] = self.0[i].is_finite();
                }
                Mask(r)
            }

            /// `if m { a } else { b }`, lane by lane, as a bitwise blend (the same bits). Written as a plain
            /// conditional, `x = select(m, y, x)` on a buffer compiles to masked stores (`vmaskmovpd`), which AMD's
            /// Zen cores run as many micro-operations: the mask updates of the direct solve's multipliers and
            /// positions alone cost 12% of a 1000 x 16 frame there (`tools/ab.sh OLD NEW 12 30 1000x16` with
            /// `scene_cost` built before and after commit 2fb4659: 0.879).
            #[inline(always)]
            pub fn select(m: Mask<L>, a: Self, b: Self) -> Self {
                let mut r = b.0;
                for i in 0..L {
                    let take_a = (m.0[i] as $bits).wrapping_neg();
                    let (a, b) = (a.0[i].to_bits(), b.0[i].to_bits());
                    r[i] = <$elem>::from_bits(b ^ ((a ^ b) & take_a));
                }
                Self(r)
            }
        }

        impl<const L: usize> Add for $ty<L> {
            type Output = Self;
            #[inline(always)]
            fn add(self, o: Self) -> Self {
                self.zip(o, |a, b| a + b)
            }
        }

        impl<const L: usize> Sub for $ty<L> {
            type Output = Self;
            #[inline(always)]
            fn sub(self, o: Self) -> Self {
                self.zip(o, |a, b| a - b)
            }
        }

        impl<const L: usize> Mul for $ty<L> {
            type Output = Self;
            #[inline(always)]
            fn mul(self, o: Self) -> Self {
                self.zip(o, |a, b| a * b)
            }
        }

        impl<const L: usize> Div for $ty<L> {
            type Output = Self;
            #[inline(always)]
            fn div(self, o: Self) -> Self {
                self.zip(o, |a, b| a / b)
            }
        }

        impl<const L: usize> Mul<$elem> for $ty<L> {
            type Output = Self;
            #[inline(always)]
            fn mul(self, s: $elem) -> Self {
                self.map(|a| a * s)
            }
        }

        impl<const L: usize> Add<$elem> for $ty<L> {
            type Output = Self;
            #[inline(always)]
            fn add(self, s: $elem) -> Self {
                self.map(|a| a + s)
            }
        }

        impl<const L: usize> Neg for $ty<L> {
            type Output = Self;
            #[inline(always)]
            fn neg(self) -> Self {
                self.map(|a| -a)
            }
        }
    };
}

lanewise!(F, f32, u32);
lanewise!(D, f64, u64);

impl<const L: usize> F<L> {
    #[inline(always)]
    pub fn to_f64(self) -> D<L> {
        let mut r = [0.0; L];
        for i in 0..L {
            r[i] = self.0[i] as f64;
        }
        D(r)
    }
}

impl<const L: usize> D<L> {
    #[inline(always)]
    pub fn to_f32(self) -> F<L> {
        let mut r = [0.0; L];
        for i in 0..L {
            r[i] = self.0[i] as f32;
        }
        F(r)
    }
}

impl<const L: usize> Mask<L> {
    #[inline(always)]
    pub fn and(self, o: Self) -> Self {
        let mut r = self.0;
        for i in 0..L {
            r[i] &= o.0[i];
        }
        Self(r)
    }

    #[inline(always)]
    pub fn or(self, o: Self) -> Self {
        let mut r = self.0;
        for i in 0..L {
            r[i] |= o.0[i];
        }
        Self(r)
    }

    #[inline(always)]
    pub fn not(self) -> Self {
        let mut r = self.0;
        for i in 0..L {
            r[i] = !r[i];
        }
        Self(r)
    }

    #[inline(always)]
    pub fn any(self) -> bool {
        self.0.iter().any(|&b| b)
    }

    /// Every lane: callers take a plain update instead of a blend, which costs three operations a vector.
    #[inline(always)]
    pub fn all(self) -> bool {
        self.0.iter().all(|&b| b)
    }
}

/// `L` single-precision 3-vectors.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct V3<const L: usize> {
    pub x: F<L>,
    pub y: F<L>,
    pub z: F<L>,
}

/// `L` double-precision 3-vectors (particle positions).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DV3<const L: usize> {
    pub x: D<L>,
    pub y: D<L>,
    pub z: D<L>,
}

/// `L` quaternions `x, y, z, w`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Q<const L: usize> {
    pub x: F<L>,
    pub y: F<L>,
    pub z: F<L>,
    pub w: F<L>,
}

/// `L` 3x3 matrices by columns.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct M3<const L: usize> {
    pub x_axis: V3<L>,
    pub y_axis: V3<L>,
    pub z_axis: V3<L>,
}

macro_rules! vec3_ops {
    ($ty:ident, $lane:ident, $elem:ty) => {
        // The same set for both vector types; not every operation is used on both.
        #[allow(dead_code)]
        impl<const L: usize> $ty<L> {
            pub const ZERO: Self = Self { x: $lane([0.0; L]), y: $lane([0.0; L]), z: $lane([0.0; L]) };

            #[inline(always)]
            pub fn dot(self, o: Self) -> $lane<L> {
                self.x * o.x + self.y * o.y + self.z * o.z
            }

            #[inline(always)]
            pub fn length_squared(self) -> $lane<L> {
                self.dot(self)
            }

            #[inline(always)]
            pub fn scale(self, s: $lane<L>) -> Self {
                Self { x: self.x * s, y: self.y * s, z: self.z * s }
            }

            #[inline(always)]
            pub fn select(m: Mask<L>, a: Self, b: Self) -> Self {
                Self { x: $lane::select(m, a.x, b.x), y: $lane::select(m, a.y, b.y), z: $lane::select(m, a.z, b.z) }
            }

            #[inline(always)]
            pub fn get(&self, lane: usize) -> [$elem; 3] {
                [self.x.0[lane], self.y.0[lane], self.z.0[lane]]
            }

            #[inline(always)]
            pub fn set(&mut self, lane: usize, v: [$elem; 3]) {
                self.x.0[lane] = v[0];
                self.y.0[lane] = v[1];
                self.z.0[lane] = v[2];
            }
        }

        impl<const L: usize> Add for $ty<L> {
            type Output = Self;
            #[inline(always)]
            fn add(self, o: Self) -> Self {
                Self { x: self.x + o.x, y: self.y + o.y, z: self.z + o.z }
            }
        }

        impl<const L: usize> Sub for $ty<L> {
            type Output = Self;
            #[inline(always)]
            fn sub(self, o: Self) -> Self {
                Self { x: self.x - o.x, y: self.y - o.y, z: self.z - o.z }
            }
        }

        impl<const L: usize> Mul<$elem> for $ty<L> {
            type Output = Self;
            #[inline(always)]
            fn mul(self, s: $elem) -> Self {
                Self { x: self.x * s, y: self.y * s, z: self.z * s }
            }
        }

        impl<const L: usize> Div<$elem> for $ty<L> {
            type Output = Self;
            #[inline(always)]
            fn div(self, s: $elem) -> Self {
                Self { x: self.x.map(|a| a / s), y: self.y.map(|a| a / s), z: self.z.map(|a| a / s) }
            }
        }
    };
}

vec3_ops!(V3, F, f32);
vec3_ops!(DV3, D, f64);

impl<const L: usize> V3<L> {
    #[inline(always)]
    pub fn cross(self, o: Self) -> Self {
        Self { x: self.y * o.z - o.y * self.z, y: self.z * o.x - o.z * self.x, z: self.x * o.y - o.x * self.y }
    }

    #[inline(always)]
    pub fn to_f64(self) -> DV3<L> {
        DV3 { x: self.x.to_f64(), y: self.y.to_f64(), z: self.z.to_f64() }
    }
}

impl<const L: usize> DV3<L> {
    #[inline(always)]
    pub fn to_f32(self) -> V3<L> {
        V3 { x: self.x.to_f32(), y: self.y.to_f32(), z: self.z.to_f32() }
    }
}

impl<const L: usize> Q<L> {
    pub const IDENTITY: Self = Self { x: F([0.0; L]), y: F([0.0; L]), z: F([0.0; L]), w: F([1.0; L]) };

    #[inline(always)]
    pub fn xyz(self) -> V3<L> {
        V3 { x: self.x, y: self.y, z: self.z }
    }

    #[inline(always)]
    pub fn dot(self, o: Self) -> F<L> {
        self.x * o.x + self.y * o.y + self.z * o.z + self.w * o.w
    }

    /// The Hamilton product `self * o` (apply `o` first).
    #[inline(always)]
    pub fn mul(self, o: Self) -> Self {
        let (a, b) = (self, o);
        Self {
            w: a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z,
            x: a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
            y: a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
            z: a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w,
        }
    }

    /// `self` rotating `v`.
    #[inline(always)]
    pub fn rotate(self, v: V3<L>) -> V3<L> {
        let b = self.xyz();
        let b2 = b.dot(b);
        let w = self.w;
        v.scale(w * w - b2) + b.scale(v.dot(b) * 2.0) + b.cross(v).scale(w * 2.0)
    }

    #[inline(always)]
    pub fn scale(self, s: F<L>) -> Self {
        Self { x: self.x * s, y: self.y * s, z: self.z * s, w: self.w * s }
    }

    #[inline(always)]
    pub fn add(self, o: Self) -> Self {
        Self { x: self.x + o.x, y: self.y + o.y, z: self.z + o.z, w: self.w + o.w }
    }

    #[inline(always)]
    pub fn neg(self) -> Self {
        Self { x: -self.x, y: -self.y, z: -self.z, w: -self.w }
    }

    /// The inverse of a unit quaternion (glam's `inverse`).
    #[inline(always)]
    pub fn normalize(self) -> Self {
        let inv = F::splat(1.0) / self.dot(self).sqrt();
        self.scale(inv)
    }

    /// `self` or `-self`, whichever lies in the hemisphere of `reference`.
    #[inline(always)]
    pub fn align_hemisphere(self, reference: Self) -> Self {
        Self::select(self.dot(reference).lt(F::splat(0.0)), self.neg(), self)
    }

    /// Normalised linear interpolation along the shorter arc.
    #[inline(always)]
    pub fn nlerp_shorter(self, to: Self, t: F<L>) -> Self {
        let to = to.align_hemisphere(self);
        self.scale(F::splat(1.0) - t).add(to.scale(t)).normalize()
    }

    #[inline(always)]
    pub fn select(m: Mask<L>, a: Self, b: Self) -> Self {
        Self {
            x: F::select(m, a.x, b.x),
            y: F::select(m, a.y, b.y),
            z: F::select(m, a.z, b.z),
            w: F::select(m, a.w, b.w),
        }
    }

    #[inline(always)]
    pub fn get(&self, lane: usize) -> [f32; 4] {
        [self.x.0[lane], self.y.0[lane], self.z.0[lane], self.w.0[lane]]
    }

    #[inline(always)]
    pub fn set(&mut self, lane: usize, q: [f32; 4]) {
        self.x.0[lane] = q[0];
        self.y.0[lane] = q[1];
        self.z.0[lane] = q[2];
        self.w.0[lane] = q[3];
    }
}

impl<const L: usize> M3<L> {
    pub const ZERO: Self = Self { x_axis: V3::ZERO, y_axis: V3::ZERO, z_axis: V3::ZERO };

    /// The rotation matrix of unit quaternions.
    #[inline(always)]
    pub fn from_quat(q: Q<L>) -> Self {
        let (x2, y2, z2) = (q.x + q.x, q.y + q.y, q.z + q.z);
        let (xx, xy, xz) = (q.x * x2, q.x * y2, q.x * z2);
        let (yy, yz, zz) = (q.y * y2, q.y * z2, q.z * z2);
        let (wx, wy, wz) = (q.w * x2, q.w * y2, q.w * z2);
        let one = F::splat(1.0);
        Self {
            x_axis: V3 { x: one - (yy + zz), y: xy + wz, z: xz - wy },
            y_axis: V3 { x: xy - wz, y: one - (xx + zz), z: yz + wx },
            z_axis: V3 { x: xz + wy, y: yz - wx, z: one - (xx + yy) },
        }
    }

    /// Lane `lane`'s matrix, by columns.
    #[inline(always)]
    pub fn get(&self, lane: usize) -> [[f32; 3]; 3] {
        [self.x_axis.get(lane), self.y_axis.get(lane), self.z_axis.get(lane)]
    }

    #[inline(always)]
    pub fn set(&mut self, lane: usize, columns: [[f32; 3]; 3]) {
        self.x_axis.set(lane, columns[0]);
        self.y_axis.set(lane, columns[1]);
        self.z_axis.set(lane, columns[2]);
    }

    #[inline(always)]
    pub fn scale(self, s: F<L>) -> Self {
        Self { x_axis: self.x_axis.scale(s), y_axis: self.y_axis.scale(s), z_axis: self.z_axis.scale(s) }
    }
}
