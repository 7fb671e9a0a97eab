use super::{Force, Motion, M3, V3};

/// Placement of a frame B in a frame A: `x_A = rot * x_B + trans`.
/// `act_*` map vectors expressed in B to A; `inv_act_*` map A to B.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Se3 {
    /// Rotation of B in A (columns: B's axes in A).
    pub rot: M3,
    /// Origin of B in A (m).
    pub trans: V3,
}

impl Default for Se3 {
    fn default() -> Self {
        Se3::identity()
    }
}

impl Se3 {
    /// The identity placement.
    #[inline]
    pub fn identity() -> Self {
        Se3 { rot: M3::identity(), trans: V3::zeros() }
    }
    /// From a rotation and a translation.
    #[inline]
    pub fn new(rot: M3, trans: V3) -> Self {
        Se3 { rot, trans }
    }
    /// Composition: (self * other) places C in A when self places B in A and other places C in B.
    /// Column by column with fused multiply-adds on 3-vectors padded to four lanes (every step one vector
    /// operation; forward kinematics does one per body).
    #[inline]
    pub fn compose(&self, o: &Se3) -> Se3 {
        type L4 = [f64; 4];
        let r = &self.rot;
        let c = |k: usize| -> L4 { [r[(0, k)], r[(1, k)], r[(2, k)], 0.0] };
        let (r0, r1, r2) = (c(0), c(1), c(2));
        // R v + b, lane by lane
        let mv = |v: &V3, b: L4| -> L4 {
            std::array::from_fn(|l| r2[l].mul_add(v.z, r1[l].mul_add(v.y, r0[l].mul_add(v.x, b[l]))))
        };
        let z = [0.0; 4];
        let col = |k: usize| mv(&V3::new(o.rot[(0, k)], o.rot[(1, k)], o.rot[(2, k)]), z);
        let (a, b, e) = (col(0), col(1), col(2));
        let t = mv(&o.trans, [self.trans.x, self.trans.y, self.trans.z, 0.0]);
        Se3 { rot: M3::new(a[0], b[0], e[0], a[1], b[1], e[1], a[2], b[2], e[2]), trans: V3::new(t[0], t[1], t[2]) }
    }
    /// The placement of A in B.
    #[inline]
    pub fn inverse(&self) -> Se3 {
        let rt = self.rot.transpose();
        Se3 { rot: rt, trans: -(rt * self.trans) }
    }
    /// self⁻¹ * o, without forming the inverse.
    #[inline]
    pub fn inv_compose(&self, o: &Se3) -> Se3 {
        let rt = self.rot.transpose();
        Se3 { rot: rt * o.rot, trans: rt * (o.trans - self.trans) }
    }
    /// A point given in B, expressed in A.
    #[inline]
    pub fn act_point(&self, p: &V3) -> V3 {
        self.rot * p + self.trans
    }
    /// A twist in B coordinates, expressed in A (about A's origin).
    #[inline]
    pub fn act_motion(&self, m: &Motion) -> Motion {
        let ang = self.rot * m.ang;
        Motion { lin: self.rot * m.lin + self.trans.cross(&ang), ang }
    }
    /// A twist in A coordinates, expressed in B.
    #[inline]
    pub fn inv_act_motion(&self, m: &Motion) -> Motion {
        let rt = self.rot.transpose();
        Motion { lin: rt * (m.lin - self.trans.cross(&m.ang)), ang: rt * m.ang }
    }
    /// A wrench in B coordinates (moment about B's origin), expressed in A (about A's origin).
    #[inline]
    pub fn act_force(&self, f: &Force) -> Force {
        let lin = self.rot * f.lin;
        Force { lin, ang: self.rot * f.ang + self.trans.cross(&lin) }
    }
    /// A wrench in A coordinates, expressed in B.
    #[inline]
    pub fn inv_act_force(&self, f: &Force) -> Force {
        let rt = self.rot.transpose();
        Force { lin: rt * f.lin, ang: rt * (f.ang - self.trans.cross(&f.lin)) }
    }
}
