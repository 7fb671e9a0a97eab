use super::{V3, V6};
use std::ops::{Add, AddAssign, Mul, Neg, Sub, SubAssign};

/// A twist or spatial acceleration: `lin` is the (classical/spatial) linear part at the frame origin,
/// `ang` the angular part.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Motion {
    /// Linear part (velocity or acceleration of the frame origin), m/s or m/s².
    pub lin: V3,
    /// Angular part (angular velocity or acceleration), rad/s or rad/s².
    pub ang: V3,
}

/// A wrench or spatial momentum: `lin` is the force (linear momentum), `ang` the moment about the
/// frame origin (angular momentum about it).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Force {
    /// Force (N) or linear momentum (kg m/s).
    pub lin: V3,
    /// Moment about the frame origin (N m) or angular momentum about it (kg m²/s).
    pub ang: V3,
}

macro_rules! vec6_ops {
    ($t:ident) => {
        impl $t {
            /// All six entries zero.
            pub const ZERO: $t = $t { lin: V3::new(0.0, 0.0, 0.0), ang: V3::new(0.0, 0.0, 0.0) };
            /// From the linear and angular parts.
            #[inline]
            pub fn new(lin: V3, ang: V3) -> Self {
                Self { lin, ang }
            }
            /// From a 6-vector `[linear; angular]`.
            #[inline]
            pub fn from_v6(x: &V6) -> Self {
                Self { lin: V3::new(x[0], x[1], x[2]), ang: V3::new(x[3], x[4], x[5]) }
            }
            /// From the first six numbers of a slice, `[linear; angular]`.
            /// # Panics
            /// If `x` has fewer than 6 entries (an internal helper: the engine passes checked slices).
            #[inline]
            pub fn from_slice(x: &[f64]) -> Self {
                Self { lin: V3::new(x[0], x[1], x[2]), ang: V3::new(x[3], x[4], x[5]) }
            }
            /// As a 6-vector `[linear; angular]`.
            #[inline]
            pub fn to_v6(&self) -> V6 {
                V6::new(self.lin.x, self.lin.y, self.lin.z, self.ang.x, self.ang.y, self.ang.z)
            }
            /// Write `[linear; angular]` into the first six entries of `out`.
            /// # Panics
            /// If `out` has fewer than 6 entries.
            #[inline]
            pub fn write(&self, out: &mut [f64]) {
                out[..3].copy_from_slice(self.lin.as_slice());
                out[3..6].copy_from_slice(self.ang.as_slice());
            }
        }
        impl Add for $t {
            type Output = $t;
            #[inline]
            fn add(self, o: $t) -> $t {
                $t { lin: self.lin + o.lin, ang: self.ang + o.ang }
            }
        }
        impl Sub for $t {
            type Output = $t;
            #[inline]
            fn sub(self, o: $t) -> $t {
                $t { lin: self.lin - o.lin, ang: self.ang - o.ang }
            }
        }
        impl AddAssign for $t {
            #[inline]
            fn add_assign(&mut self, o: $t) {
                self.lin += o.lin;
                self.ang += o.ang;
            }
        }
        impl SubAssign for $t {
            #[inline]
            fn sub_assign(&mut self, o: $t) {
                self.lin -= o.lin;
                self.ang -= o.ang;
            }
        }
        impl Neg for $t {
            type Output = $t;
            #[inline]
            fn neg(self) -> $t {
                $t { lin: -self.lin, ang: -self.ang }
            }
        }
        impl Mul<f64> for $t {
            type Output = $t;
            #[inline]
            fn mul(self, s: f64) -> $t {
                $t { lin: self.lin * s, ang: self.ang * s }
            }
        }
    };
}
vec6_ops!(Motion);
vec6_ops!(Force);

/// `a × b` with one fused multiply-add per entry (`a_j b_k − a_k b_j` as `fma(a_j, b_k, −a_k b_j)`).
#[inline(always)]
pub(crate) fn cross(a: &V3, b: &V3) -> V3 {
    V3::new(a.y.mul_add(b.z, -(a.z * b.y)), a.z.mul_add(b.x, -(a.x * b.z)), a.x.mul_add(b.y, -(a.y * b.x)))
}

/// `a × b + c × d`, fused: two products of each pair folded into multiply-adds.
#[inline(always)]
fn cross2(a: &V3, b: &V3, c: &V3, d: &V3) -> V3 {
    V3::new(
        a.y.mul_add(b.z, c.y.mul_add(d.z, -(a.z * b.y)) - c.z * d.y),
        a.z.mul_add(b.x, c.z.mul_add(d.x, -(a.x * b.z)) - c.x * d.z),
        a.x.mul_add(b.y, c.x.mul_add(d.y, -(a.y * b.x)) - c.y * d.x),
    )
}

impl Motion {
    /// Motion cross product `self ×m other` (derivative of a moving twist).
    #[inline]
    pub fn cross_motion(&self, m: &Motion) -> Motion {
        Motion { lin: cross2(&self.ang, &m.lin, &self.lin, &m.ang), ang: cross(&self.ang, &m.ang) }
    }
    /// Force cross product `self ×* f` (rate of change of a momentum carried by a moving frame).
    #[inline]
    pub fn cross_force(&self, f: &Force) -> Force {
        Force { lin: cross(&self.ang, &f.lin), ang: cross2(&self.ang, &f.ang, &self.lin, &f.lin) }
    }
    /// Power of a wrench on this twist. Two independent chains of fused multiply-adds, one per half, joined
    /// by one addition: a dependency chain of four operations instead of eleven (CRBA forms one per entry).
    #[inline]
    pub fn dot(&self, f: &Force) -> f64 {
        let (a, b, c, e) = (&self.lin, &f.lin, &self.ang, &f.ang);
        a.z.mul_add(b.z, a.y.mul_add(b.y, a.x * b.x)) + c.z.mul_add(e.z, c.y.mul_add(e.y, c.x * e.x))
    }
}
