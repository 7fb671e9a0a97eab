use super::lanes::{Lanes, Real, F4};
use super::{cross_fma, skew, Force, Motion, Se3, M3, M6, V3};

/// Rigid-body inertia in the parameters the whole project uses (ARCHITECTURE.md): mass, first
/// moment `h = m c` and the rotational inertia `i_o` about the body-frame origin, all in body axes.
/// With this choice momentum and Newton-Euler equations are linear in the 10 numbers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Inertia {
    /// Mass (kg).
    pub mass: f64,
    /// First moment of mass `m c` (kg m), body axes.
    pub h: V3,
    /// Rotational inertia about the body-frame origin, body axes (kg m²).
    pub i_o: M3,
}

impl Inertia {
    /// A massless body.
    pub fn zero() -> Self {
        Inertia { mass: 0.0, h: V3::zeros(), i_o: M3::zeros() }
    }

    /// From mass, centre of mass and inertia about the centre of mass (parallel-axis theorem).
    pub fn from_com(mass: f64, com: V3, i_c: M3) -> Self {
        let cx = skew(&com);
        Inertia { mass, h: com * mass, i_o: i_c - cx * cx * mass }
    }

    /// From the 10 standard parameters `[m, mcx, mcy, mcz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]`.
    ///
    /// # Panics
    /// If `p` has fewer than 10 entries (callers pass checked slices, e.g. `Model::with_parameters`).
    pub fn from_params(p: &[f64]) -> Self {
        Inertia {
            mass: p[0],
            h: V3::new(p[1], p[2], p[3]),
            i_o: M3::new(p[4], p[5], p[7], p[5], p[6], p[8], p[7], p[8], p[9]),
        }
    }

    /// The 10 standard parameters `[m, mcx, mcy, mcz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz]`.
    pub fn to_params(&self) -> [f64; 10] {
        let i = &self.i_o;
        [self.mass, self.h.x, self.h.y, self.h.z, i[(0, 0)], i[(0, 1)], i[(1, 1)], i[(0, 2)], i[(1, 2)], i[(2, 2)]]
    }

    /// Centre of mass (zero for a massless body).
    pub fn com(&self) -> V3 {
        if self.mass > 0.0 {
            self.h / self.mass
        } else {
            V3::zeros()
        }
    }

    /// Inertia about the centre of mass.
    pub fn i_com(&self) -> M3 {
        if self.mass > 0.0 {
            let cx = skew(&self.com());
            self.i_o + cx * cx * self.mass
        } else {
            self.i_o
        }
    }

    /// Spatial momentum (about the body origin, body axes) of a body moving with twist `v`.
    #[inline]
    pub fn mul_motion(&self, v: &Motion) -> Force {
        // fused multiply-adds throughout (ABA forms one momentum per body)
        let (m, i, w) = (self.mass, &self.i_o, &v.ang);
        let (hw, hv) = (cross_fma(&self.h, w), cross_fma(&self.h, &v.lin));
        let iw = |r: usize| i[(r, 2)].mul_add(w.z, i[(r, 1)].mul_add(w.y, i[(r, 0)].mul_add(w.x, hv[r])));
        Force {
            lin: V3::new(v.lin.x.mul_add(m, -hw.x), v.lin.y.mul_add(m, -hw.y), v.lin.z.mul_add(m, -hw.z)),
            ang: V3::new(iw(0), iw(1), iw(2)),
        }
    }

    /// `mul_motion` as a linear map of the parameters: column k is the momentum contributed by
    /// parameter k of `to_params`, so `self.mul_motion(v) == Σₖ self.to_params()[k] · cols[k]`.
    /// From `[m v − h × ω; I_o ω + h × v]` with `v = (v, ω)`: the body block of every regressor.
    pub fn mul_motion_columns(v: &Motion) -> [Force; 10] {
        let (lin, w) = (v.lin, v.ang);
        let z = V3::zeros();
        // h × (−ω) = ω × h and h × v = −v × h: the columns of h are ω × eₖ and −v × eₖ.
        let h = |e: V3| Force::new(w.cross(&e), -lin.cross(&e));
        let i = |x: V3| Force::new(z, x);
        [
            Force::new(lin, z),
            h(V3::x()),
            h(V3::y()),
            h(V3::z()),
            i(V3::new(w.x, 0.0, 0.0)),
            i(V3::new(w.y, w.x, 0.0)),
            i(V3::new(0.0, w.y, 0.0)),
            i(V3::new(w.z, 0.0, w.x)),
            i(V3::new(0.0, w.z, w.y)),
            i(V3::new(0.0, 0.0, w.z)),
        ]
    }

    /// 6×6 matrix form, mapping `[v; w]` to `[f; n]`: `[[m 1, −[h]], [[h], I_o]]`.
    #[inline]
    pub fn to_matrix(&self) -> M6 {
        let (m, h, i) = (self.mass, &self.h, &self.i_o);
        #[rustfmt::skip]
        let out = M6::new(
            m, 0.0, 0.0, 0.0, h.z, -h.y,
            0.0, m, 0.0, -h.z, 0.0, h.x,
            0.0, 0.0, m, h.y, -h.x, 0.0,
            0.0, -h.z, h.y, i[(0, 0)], i[(0, 1)], i[(0, 2)],
            h.z, 0.0, -h.x, i[(1, 0)], i[(1, 1)], i[(1, 2)],
            -h.y, h.x, 0.0, i[(2, 0)], i[(2, 1)], i[(2, 2)],
        );
        out
    }

    /// The same inertia seen from the parent frame of `x` (x places this body's frame in the parent).
    ///
    /// Parallel-axis shift by `p` in the form `I' = R I Rᵀ − [p][h_r] − [h_r + m p][p]`, expanded with
    /// `[a][b] = b aᵀ − (a·b) 1` into `R I Rᵀ − h_r pᵀ − p h'ᵀ + (p·(h_r + h')) 1` with `h' = h_r + m p` (the
    /// transformed first moment): only the six independent entries of the symmetric result are computed, each as one
    /// chain of fused multiply-adds (the skew-matrix products would cost 54 multiplications by zero, which the
    /// compiler may not drop for floats). Featherstone, RBDA (2008), eq. 2.63.
    ///
    /// Always inlined: ABA forms one per body and stage, and as a call its result went through memory (the
    /// caller re-read it at once to expand it to 6×6): inlined, the 10-body RK4 simulation `sim10s_table` runs
    /// 6.5 % faster in CPU time (median of 25 interleaved runs) for 0.8 % fewer instructions.
    #[inline(always)]
    pub fn transformed(&self, x: &Se3) -> Inertia {
        // Written on whole columns (lane j of a column is row j; `F4`), each entry still the one chain of fused
        // multiply-adds above, so the result is the same to the bit as entry-by-entry code. The compiler keeps the
        // chains scalar but, the columns' data flow being explicit, with fewer moves and spills than the
        // entry-by-entry form: ABA forms one per body, 48,107 → 47,257 instructions per RK4 step of `sim10s_table`
        // (callgrind).
        let (r, io, m) = (&x.rot, &self.i_o, self.mass);
        let col = |k: usize| Lanes([r[(0, k)], r[(1, k)], r[(2, k)], 0.0]);
        let (r0, r1, r2) = (col(0), col(1), col(2));
        let s = F4::splat;
        let pa = [x.trans.x, x.trans.y, x.trans.z];
        let p = Lanes([pa[0], pa[1], pa[2], 0.0]);
        // h_r = R h, h' = h_r + m p
        let h_r = r2.mul_add(s(self.h.z), r1.mul_add(s(self.h.y), r0 * s(self.h.x)));
        let hp = p.mul_add(s(m), h_r);
        // A = R I, column c: Σₖ R[:, k] I(k, c)
        let a = |c: usize| r2.mul_add(s(io[(2, c)]), r1.mul_add(s(io[(1, c)]), r0 * s(io[(0, c)])));
        let (a0, a1, a2) = (a(0), a(1), a(2));
        let diag = pa[0].mul_add(h_r.0[0] + hp.0[0], pa[1].mul_add(h_r.0[1] + hp.0[1], pa[2] * (h_r.0[2] + hp.0[2])));
        // column k of A Rᵀ − h_r pᵀ − p h'ᵀ, with (A Rᵀ)(j, k) = Σ_c A(j, c) R(k, c)
        let (nh, np) = (-h_r, -p);
        let e = |k: usize| {
            let rak = a2.mul_add(s(r[(k, 2)]), a1.mul_add(s(r[(k, 1)]), a0 * s(r[(k, 0)])));
            np.mul_add(s(hp.0[k]), nh.mul_add(s(pa[k]), rak))
        };
        let (e0, e1, e2) = (e(0), e(1), e(2));
        // the upper triangle (j ≤ k), mirrored: the result is exactly symmetric
        let (xx, yy, zz) = (e0.0[0] + diag, e1.0[1] + diag, e2.0[2] + diag);
        let (xy, xz, yz) = (e1.0[0], e2.0[0], e2.0[1]);
        Inertia { mass: m, h: V3::new(hp.0[0], hp.0[1], hp.0[2]), i_o: M3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz) }
    }

    /// Sum of two inertias expressed in the same frame (a composite body).
    pub fn add(&self, o: &Inertia) -> Inertia {
        Inertia { mass: self.mass + o.mass, h: self.h + o.h, i_o: self.i_o + o.i_o }
    }

    /// Kinetic energy of the body moving with twist `v`.
    pub fn kinetic_energy(&self, v: &Motion) -> f64 {
        0.5 * v.dot(&self.mul_motion(v))
    }
}

/// Express a 6×6 articulated inertia given in a child frame in the parent frame:
/// `I_p = X* I_c X⁻¹`, computed blockwise (about 40 % cheaper than two dense 6×6 products).
/// `x` places the child frame in the parent. Blocks: I = [[A, B], [Bᵀ, D]] for [lin; ang].
pub fn transform_inertia_to_parent(x: &Se3, ic: &M6) -> M6 {
    let r = &x.rot;
    let rt = r.transpose();
    let a = r * ic.fixed_view::<3, 3>(0, 0) * rt;
    let b = r * ic.fixed_view::<3, 3>(0, 3) * rt;
    let d = r * ic.fixed_view::<3, 3>(3, 3) * rt;
    let px = skew(&x.trans);
    let apx = a * px;
    let bp = b - apx; // B' - A'[p]
    let pb = px * b;
    // D' - [p]A'[p] + [p]B' - B'ᵀ[p]; since [p]ᵀ = -[p], the last term equals ([p]B')ᵀ.
    let dp = d - px * apx + pb + pb.transpose();
    let mut out = M6::zeros();
    out.fixed_view_mut::<3, 3>(0, 0).copy_from(&a);
    out.fixed_view_mut::<3, 3>(0, 3).copy_from(&bp);
    out.fixed_view_mut::<3, 3>(3, 0).copy_from(&bp.transpose());
    out.fixed_view_mut::<3, 3>(3, 3).copy_from(&dp);
    out
}

/// Product of a 6×6 (articulated) inertia with a twist, as a wrench.
#[inline]
pub fn m6_mul_motion(i: &M6, v: &Motion) -> Force {
    Force::from_v6(&(i * v.to_v6()))
}
