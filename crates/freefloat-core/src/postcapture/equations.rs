//! The identification equations of Zhang, Yue, Yuan 2020 ("An online one-step method to identify
//! inertial parameters of the base and the target simultaneously for space robots in postcapture", IEEE
//! Access 8), one regression block per sample, for the base (body 1, reference point = base sensor) and
//! the captured target (body n, reference point = capture point), the arm links known.
//!
//! Two forms of the same physics:
//! - the paper's (eqs. 11-33): mass and first moment `μ = [m₁, m₁b'₁, mₙ, mₙb'ₙ]` from the linear rows
//!   (`A μ = b`), CoM inertias `θ = [I'₁#; I'ₙ#]` from the angular rows with the second-order term,
//!   `Φ θ = y + Ψ D(μ)` (eqs. 34-35), solved by the modified RLS (`estimation::ModifiedRls`);
//! - the standard form (per body `[m, m b', inertia about the reference point]`), exactly linear, taken
//!   from the engine's momentum and inverse-dynamics regressors.
//!
//! The paper's appendices A-C (H, Q, S) are garbled in the only text available; the closed forms below
//! were re-derived (documented in `docs/postcapture.md`) and are checked in the tests against the
//! quantities they stand for (`m c × ċ`, `m c × c̈`, `I β + ω × I ω`, computed directly).
//!
//! Conventions: every vector inertial; `A` the body → inertial rotation of the reference point's body;
//! `I#` (eq. 21) = `[I11, I12, I13, I22, I23, I33]` (the engine's order `[Ixx, Ixy, Iyy, Ixz, Iyz, Izz]`
//! is `I#[[0, 1, 3, 2, 4, 5]]`); `mono(b) = [bx², bx by, bx bz, by², by bz, bz²]`;
//! `m J(b') = [m, m b', m mono(b')]` (eq. 23).

use crate::check::check_vec;
use crate::data::Data;
use crate::error::{FfError, Result};
use crate::kinematics::classical_acceleration;
use crate::model::{JointType, Model};
use crate::regressors::{dynamics_regressor, momentum_regressor};
use crate::spatial::{skew, M3, V3};
use nalgebra::{DMatrix, SMatrix};

/// 3×4 block (a per-body column block of the planar/3D rows).
pub type M3x4 = SMatrix<f64, 3, 4>;
/// 3×6 block.
pub type M3x6 = SMatrix<f64, 3, 6>;
/// 3×10 block (one body's ten standard parameters).
pub type M3x10 = SMatrix<f64, 3, 10>;

/// Motion of a reference point with the axes of its body, all inertial: position `r`, attitude `rot`
/// (body → inertial), velocity `v`, angular velocity `w`, acceleration `a`, angular acceleration `b`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointMotion {
    /// Position (m), inertial frame.
    pub r: V3,
    /// Attitude, body → inertial.
    pub rot: M3,
    /// Velocity (m/s), inertial frame.
    pub v: V3,
    /// Angular velocity (rad/s), inertial frame.
    pub w: V3,
    /// Acceleration (m/s²), inertial frame.
    pub a: V3,
    /// Angular acceleration (rad/s²), inertial frame.
    pub b: V3,
}

impl PointMotion {
    /// Positions relative to a moving origin (the force form's base-sensor point, Zhang 2020 §III-B):
    /// velocities and accelerations stay absolute.
    pub fn shifted(&self, origin: &V3) -> PointMotion {
        PointMotion { r: self.r - origin, ..*self }
    }

    /// The motion of body `body`'s frame origin from the kinematics in `d` (after `forward_accelerations`,
    /// e.g. through `dynamics_regressor`, or `forward_velocities` with `with_acc = false`).
    pub fn of_body(d: &Data, body: usize, with_acc: bool) -> PointMotion {
        let x = &d.o_mi[body];
        let tw = &d.v[body];
        let (a, b) = if with_acc {
            let ac = classical_acceleration(&d.a[body], tw);
            (x.rot * ac.lin, x.rot * ac.ang)
        } else {
            (V3::zeros(), V3::zeros())
        };
        PointMotion { r: x.trans, rot: x.rot, v: x.rot * tw.lin, w: x.rot * tw.ang, a, b }
    }
}

/// `[#v]` (3 × 6) with `I v = [#v] I#` (Zhang 2020, eq. (20)).
pub fn sharp(v: &V3) -> M3x6 {
    let (a, b, c) = (v.x, v.y, v.z);
    M3x6::from_row_slice(&[a, b, c, 0.0, 0.0, 0.0, 0.0, a, 0.0, b, c, 0.0, 0.0, 0.0, a, 0.0, b, c])
}

/// `W(u)` (3 × 6) with `(|b|² 1 − b bᵀ) u = W(u) mono(b)`: the quadratic part of `m c × ċ` (our closed form
/// of Zhang 2020's Appendix A, eq. (19)).
pub fn quad(u: &V3) -> M3x6 {
    let (a, b, c) = (u.x, u.y, u.z);
    M3x6::from_row_slice(&[0.0, -b, -c, a, 0.0, a, b, -a, 0.0, 0.0, -c, b, c, 0.0, -a, c, -b, 0.0])
}

/// `mono(b) = [bx², bx by, bx bz, by², by bz, bz²]`.
pub fn mono(b: &V3) -> [f64; 6] {
    [b.x * b.x, b.x * b.y, b.x * b.z, b.y * b.y, b.y * b.z, b.z * b.z]
}

/// `m J(b')` (10) = `[m, m b', m mono(b')]` (Zhang 2020, eq. (23)).
pub fn m_j(m: f64, b: &V3) -> [f64; 10] {
    let q = mono(b);
    [m, m * b.x, m * b.y, m * b.z, m * q[0], m * q[1], m * q[2], m * q[3], m * q[4], m * q[5]]
}

/// `I#` (eq. (21)) of a symmetric matrix: `[I11, I12, I13, I22, I23, I33]`.
pub fn inertia_sharp(i: &M3) -> [f64; 6] {
    [i[(0, 0)], i[(0, 1)], i[(0, 2)], i[(1, 1)], i[(1, 2)], i[(2, 2)]]
}

/// `m v_c = B [m; m b']` (3 × 4; Zhang 2020, eq. (12), one body's block).
pub fn b_block(p: &PointMotion) -> M3x4 {
    let mut out = M3x4::zeros();
    out.set_column(0, &p.v);
    out.fixed_columns_mut::<3>(1).copy_from(&(skew(&p.w) * p.rot));
    out
}

/// `m c × ċ = H m J(b')` (3 × 10; Zhang 2020, eq. (19)): `[r̃ v | (r̃ ω̃ − ṽ) A | A W(Aᵀ ω)]`.
pub fn h_block(p: &PointMotion) -> M3x10 {
    let (rt, wt, vt) = (skew(&p.r), skew(&p.w), skew(&p.v));
    let wb = p.rot.transpose() * p.w;
    let mut out = M3x10::zeros();
    out.set_column(0, &(rt * p.v));
    out.fixed_columns_mut::<3>(1).copy_from(&((rt * wt - vt) * p.rot));
    out.fixed_columns_mut::<6>(4).copy_from(&(p.rot * quad(&wb)));
    out
}

/// `I_c ω = D I'#` (3 × 6; Zhang 2020, eq. (17), one body's block): `A [#(Aᵀ ω)]`.
pub fn d_block(p: &PointMotion) -> M3x6 {
    p.rot * sharp(&(p.rot.transpose() * p.w))
}

/// `m a_c = G [m; m b']` (3 × 4; Zhang 2020, eq. (29), one body's block): `[a | (β̃ + ω̃ω̃) A]`.
pub fn g_block(p: &PointMotion) -> M3x4 {
    let wt = skew(&p.w);
    let mut out = M3x4::zeros();
    out.set_column(0, &p.a);
    out.fixed_columns_mut::<3>(1).copy_from(&((skew(&p.b) + wt * wt) * p.rot));
    out
}

/// `m c × c̈ = S m J(b')` (3 × 10; Zhang 2020, eq. (31), our closed form of Appendix C, `S = dH/dt`):
/// `[r̃ a | (r̃ (β̃ + ω̃ω̃) − ã) A | A (W(β') + ω̃' W(ω'))]`, `ω' = Aᵀ ω`, `β' = Aᵀ β`.
pub fn s_block(p: &PointMotion) -> M3x10 {
    let (rt, wt, bt, at) = (skew(&p.r), skew(&p.w), skew(&p.b), skew(&p.a));
    let wb = p.rot.transpose() * p.w;
    let bb = p.rot.transpose() * p.b;
    let mut out = M3x10::zeros();
    out.set_column(0, &(rt * p.a));
    out.fixed_columns_mut::<3>(1).copy_from(&((rt * (bt + wt * wt) - at) * p.rot));
    out.fixed_columns_mut::<6>(4).copy_from(&(p.rot * (quad(&bb) + skew(&wb) * quad(&wb))));
    out
}

/// `I_c β + ω × I_c ω = Q I'#` (3 × 6; Zhang 2020, eq. (32), one body's block; our closed form of
/// Appendix B): `A ([#β'] + ω̃' [#ω'])`.
pub fn q_block(p: &PointMotion) -> M3x6 {
    let wb = p.rot.transpose() * p.w;
    let bb = p.rot.transpose() * p.b;
    p.rot * (sharp(&bb) + skew(&wb) * sharp(&wb))
}

/// Which rows and columns of the 3D equations a model uses. Planar (our reduction of the paper's 2D case):
/// linear rows x, y; angular row z; μ per body `[m, m bx, m by]`; θ per body `I_zz`; D per body
/// `[m, m bx, m by, m(bx² + by²)]` (the bx² and by² columns of H and S are equal, the bx·by column vanishes).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Layout {
    /// True for the planar reduction (x, y, yaw), false for 3D.
    pub planar: bool,
}

impl Layout {
    /// The layout of a model with a planar or free base (an error otherwise).
    pub fn of(m: &Model) -> Result<Layout> {
        match m.joint_types[0] {
            JointType::Free => Ok(Layout { planar: false }),
            JointType::Planar => Ok(Layout { planar: true }),
            _ => Err(FfError::arg("model", "the post-capture equations need a free or planar base")),
        }
    }
    /// Rows of the linear (momentum/force) equations used.
    pub fn lin_rows(&self) -> &'static [usize] {
        if self.planar {
            &[0, 1]
        } else {
            &[0, 1, 2]
        }
    }
    /// Rows of the angular equations used.
    pub fn ang_rows(&self) -> &'static [usize] {
        if self.planar {
            &[2]
        } else {
            &[0, 1, 2]
        }
    }
    /// of one body's 4 columns `[m, m bx, m by, m bz]`
    pub fn mu_cols(&self) -> &'static [usize] {
        if self.planar {
            &[0, 1, 2]
        } else {
            &[0, 1, 2, 3]
        }
    }
    /// of one body's `I#` (6)
    pub fn th_cols(&self) -> &'static [usize] {
        if self.planar {
            &[5]
        } else {
            &[0, 1, 2, 3, 4, 5]
        }
    }
    /// of one body's `m J` (10)
    pub fn d_cols(&self) -> &'static [usize] {
        if self.planar {
            &[0, 1, 2, 4]
        } else {
            &[0, 1, 2, 3, 4, 5, 6, 7, 8, 9]
        }
    }
    /// of one body's 10 standard parameters
    pub fn std_cols(&self) -> &'static [usize] {
        if self.planar {
            &[0, 1, 2, 9]
        } else {
            &[0, 1, 2, 3, 4, 5, 6, 7, 8, 9]
        }
    }
    /// rows of the engine's momentum `[p; L]` used
    pub fn momentum_rows(&self) -> &'static [usize] {
        if self.planar {
            &[0, 1, 5]
        } else {
            &[0, 1, 2, 3, 4, 5]
        }
    }
}

/// What the identification sees at the sample instants, row-major with a leading time axis of `T` samples:
/// `q` (T × nq), `v`, `ddq` (T × nv), `base_wrench` (T × nb: thruster generalized force `[f; τ]` in the base
/// frame at the sensor), `impulse_f` (T × 3: ∫ F dτ, inertial), `impulse_m` (T × 3: ∫ (M + x_F × F) dτ
/// about the inertial origin, or with `transport` ∫ M_B dτ about the moving base point, see
/// `momentum_point`).
#[derive(Clone, Copy, Debug)]
pub struct Measurements<'a> {
    /// Sample times (s), T.
    pub t: &'a [f64],
    /// Configurations, T × nq.
    pub q: &'a [f64],
    /// Velocities, T × nv.
    pub v: &'a [f64],
    /// Accelerations, T × nv.
    pub ddq: &'a [f64],
    /// Thruster generalized force at the sensor, base frame, T × nb.
    pub base_wrench: &'a [f64],
    /// ∫ F dτ (N s), inertial, T × 3.
    pub impulse_f: &'a [f64],
    /// ∫ (M + x_F × F) dτ about the inertial origin (N m s), T × 3; with `transport`, ∫ M_B dτ about the
    /// moving base point (the base reference body's frame origin).
    pub impulse_m: &'a [f64],
    /// `∫ [v_B]× K_lin dτ` (T × 3 × 10·nbodies, `momentum_point::momentum_transport`): when given, the
    /// momentum form's angular rows are about the moving base point, not the inertial origin.
    pub transport: Option<&'a [f64]>,
}

impl Measurements<'_> {
    fn check(&self, m: &Model) -> Result<usize> {
        let n = self.t.len();
        if n < 2 {
            return Err(FfError::arg("t", format!("need 2 or more samples, got {n}")));
        }
        check_vec("t", self.t, n)?;
        for (name, x, w) in [
            ("q", self.q, m.nq),
            ("v", self.v, m.nv),
            ("ddq", self.ddq, m.nv),
            ("base_wrench", self.base_wrench, m.nvs[0]),
            ("impulse_F", self.impulse_f, 3),
            ("impulse_M", self.impulse_m, 3),
        ]
        .into_iter()
        .chain(self.transport.map(|x| ("transport", x, 30 * m.nbodies())))
        {
            if x.len() != n * w {
                return Err(FfError::arg(
                    name,
                    format!("expected {n} samples × {w} = {} numbers, got {}", n * w, x.len()),
                ));
            }
            if let Some(k) = x.iter().position(|v| !v.is_finite()) {
                return Err(FfError::arg(
                    name,
                    format!("sample {}, entry {} is not finite", k / w.max(1), k % w.max(1)),
                ));
            }
        }
        Ok(n)
    }
}

/// Zhang 2020's regression in the modified-RLS form (eqs. 34-35): per sample `A` (nl × nμ), `b` (nl),
/// `Φ` (na × nθ), `y` (na), `Ψ` (na × nD), all row-major with a leading sample axis.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PaperRows {
    /// Sample times (s).
    pub t: Vec<f64>,
    /// `A` per sample (nl × nμ), eq. (34).
    pub a: Vec<f64>,
    /// `b` per sample (nl), eq. (34).
    pub b: Vec<f64>,
    /// `Φ` per sample (na × nθ), eq. (35).
    pub phi: Vec<f64>,
    /// `y` per sample (na), eq. (35).
    pub y: Vec<f64>,
    /// `Ψ` per sample (na × nD), eq. (35).
    pub psi: Vec<f64>,
    /// (nl, nμ, na, nθ, nD)
    pub dims: [usize; 5],
}

/// The standard-parameter regression: per sample `Φ` (rows × unknowns) and `y` (rows).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StandardRows {
    /// Sample times (s).
    pub t: Vec<f64>,
    /// `Φ` per sample (rows × unknowns).
    pub phi: Vec<f64>,
    /// `y` per sample (rows).
    pub y: Vec<f64>,
    /// (rows, unknowns)
    pub dims: [usize; 2],
}

impl PaperRows {
    /// Empty rows with room for `n` sample blocks (no reallocation in the per-sample loop).
    fn with_capacity(dims: [usize; 5], n: usize) -> PaperRows {
        let [nl, nmu, na, nth, nd] = dims;
        PaperRows {
            t: Vec::with_capacity(n),
            a: Vec::with_capacity(n * nl * nmu),
            b: Vec::with_capacity(n * nl),
            phi: Vec::with_capacity(n * na * nth),
            y: Vec::with_capacity(n * na),
            psi: Vec::with_capacity(n * na * nd),
            dims,
        }
    }
}

impl StandardRows {
    fn with_capacity(dims: [usize; 2], n: usize) -> StandardRows {
        StandardRows {
            t: Vec::with_capacity(n),
            phi: Vec::with_capacity(n * dims[0] * dims[1]),
            y: Vec::with_capacity(n * dims[0]),
            dims,
        }
    }
}

fn check_bodies(m: &Model, base: usize, target: usize) -> Result<()> {
    let n = m.nbodies();
    if base >= n || target >= n || base == target {
        return Err(FfError::arg(
            "base/target",
            format!("need two different bodies of the {n}, got {base} and {target}"),
        ));
    }
    Ok(())
}

/// The model's standard parameters (10 · nbodies) with the unknown bodies' zeroed: the known links.
fn known_parameters(m: &Model, base: usize, target: usize) -> Vec<f64> {
    let mut p: Vec<f64> = m.parameters().iter().flatten().copied().collect();
    p[10 * base..10 * base + 10].fill(0.0);
    p[10 * target..10 * target + 10].fill(0.0);
    p
}

/// Row `r` of a regressor times the parameter vector.
fn row_dot(y: &DMatrix<f64>, r: usize, p: &[f64]) -> f64 {
    (0..y.ncols()).map(|c| y[(r, c)] * p[c]).sum()
}

/// Full 3D blocks of one sample in the paper's form: `[lin | lin]` (3 × 8), rhs (3), `[ang | ang]`
/// (3 × 12), rhs (3), `[quad | quad]` (3 × 20).
#[derive(Clone, Copy)]
struct PaperSample {
    a: SMatrix<f64, 3, 8>,
    b: V3,
    phi: SMatrix<f64, 3, 12>,
    y: V3,
    psi: SMatrix<f64, 3, 20>,
}

impl PaperSample {
    fn sub(&self, o: &PaperSample) -> PaperSample {
        PaperSample { a: self.a - o.a, b: self.b - o.b, phi: self.phi - o.phi, y: self.y - o.y, psi: self.psi - o.psi }
    }
}

fn pair<const C: usize, const C2: usize>(x: &SMatrix<f64, 3, C>, z: &SMatrix<f64, 3, C>) -> SMatrix<f64, 3, C2> {
    let mut out = SMatrix::<f64, 3, C2>::zeros();
    out.fixed_columns_mut::<C>(0).copy_from(x);
    out.fixed_columns_mut::<C>(C).copy_from(z);
    out
}

/// Append one sample's rows, selected by the layout, with `Ψ = −[H₁ Hₙ]` (or `−[S₁ Sₙ]`).
fn push_paper(out: &mut PaperRows, l: &Layout, s: &PaperSample) {
    let (lr, ar) = (l.lin_rows(), l.ang_rows());
    let sel = |cols: &'static [usize], width: usize| cols.iter().copied().chain(cols.iter().map(move |c| c + width));
    for &r in lr {
        out.a.extend(sel(l.mu_cols(), 4).map(|c| s.a[(r, c)]));
        out.b.push(s.b[r]);
    }
    for &r in ar {
        out.phi.extend(sel(l.th_cols(), 6).map(|c| s.phi[(r, c)]));
        out.y.push(s.y[r]);
        out.psi.extend(sel(l.d_cols(), 10).map(|c| -s.psi[(r, c)]));
    }
}

fn paper_dims(l: &Layout) -> [usize; 5] {
    [l.lin_rows().len(), 2 * l.mu_cols().len(), l.ang_rows().len(), 2 * l.th_cols().len(), 2 * l.d_cols().len()]
}

fn planar_wrench_3d(l: &Layout, w: &[f64]) -> (V3, V3) {
    if l.planar {
        (V3::new(w[0], w[1], 0.0), V3::new(0.0, 0.0, w[2]))
    } else {
        (V3::new(w[0], w[1], w[2]), V3::new(w[3], w[4], w[5]))
    }
}

/// With a transport term, the momentum regressor `[K_lin; K_ang]` (about the origin) turned into the rows of
/// the base-point balance `L_B + ∫ v_B × P dτ` (`momentum_point`): `K_ang − [r_B]× K_lin + transport`.
fn to_base_point(k: &mut DMatrix<f64>, r_b: &V3, transport: &[f64]) {
    let w = k.ncols();
    let shift = skew(r_b) * k.rows(0, 3);
    for r in 0..3 {
        for c in 0..w {
            k[(3 + r, c)] += transport[r * w + c] - shift[(r, c)];
        }
    }
}

/// Momentum form, Zhang 2020 eqs. (11)-(19): rows as cumulative differences from the first sample t₀
/// (eq. (16) needs `H(t) − H(t₀)`; the printed `H(t)` is a typo, see docs/postcapture.md). One row block
/// per sample after the first. With `meas.transport`, the angular rows are about the moving base point
/// (`momentum_point`): H from positions relative to it, and the transport term's mass and first-moment
/// columns of each unknown body added to H's (they multiply the same `m`, `m b'` of `D(μ)`).
pub fn paper_momentum_rows(m: &Model, meas: &Measurements, base: usize, target: usize) -> Result<PaperRows> {
    let l = Layout::of(m)?;
    check_bodies(m, base, target)?;
    let n = meas.check(m)?;
    let known = known_parameters(m, base, target);
    let mut d = Data::new(m);
    let mut buf = Vec::with_capacity(m.nq);
    let mut k = DMatrix::zeros(6, 10 * m.nbodies());
    let mut out = PaperRows::with_capacity(paper_dims(&l), n);
    let mut first: Option<PaperSample> = None;
    for s in 0..n {
        let q = m.checked_q(&meas.q[s * m.nq..(s + 1) * m.nq], &mut buf).map_err(|e| at(e, s))?;
        momentum_regressor(m, &mut d, q, &meas.v[s * m.nv..(s + 1) * m.nv], &mut k).map_err(|e| at(e, s))?;
        let (mut p1, mut pn) = (PointMotion::of_body(&d, base, false), PointMotion::of_body(&d, target, false));
        let tr = meas.transport.map(|x| &x[s * 3 * k.ncols()..(s + 1) * 3 * k.ncols()]);
        if let Some(tr) = tr {
            to_base_point(&mut k, &p1.r, tr);
            (p1, pn) = (p1.shifted(&p1.r), pn.shifted(&p1.r));
        }
        let kn: [f64; 6] = std::array::from_fn(|r| row_dot(&k, r, &known)); // Σ_known [m v; m r × v + I ω]
        let imp_f = V3::from_column_slice(&meas.impulse_f[3 * s..3 * s + 3]);
        let imp_m = V3::from_column_slice(&meas.impulse_m[3 * s..3 * s + 3]);
        let mut sample = PaperSample {
            a: pair(&b_block(&p1), &b_block(&pn)),   // eq. (12)
            b: imp_f - V3::new(kn[0], kn[1], kn[2]), // eq. (13)
            phi: pair(&d_block(&p1), &d_block(&pn)), // eq. (17)
            y: imp_m - V3::new(kn[3], kn[4], kn[5]), // eq. (18)
            psi: pair(&h_block(&p1), &h_block(&pn)), // eq. (19)
        };
        if let Some(tr) = tr {
            // ∫ v_B × (m v_c) dτ of the unknown bodies: columns [m, m b'] of their standard parameters
            let w = k.ncols();
            for (off, body) in [(0, base), (10, target)] {
                for r in 0..3 {
                    for c in 0..4 {
                        sample.psi[(r, off + c)] += tr[r * w + 10 * body + c];
                    }
                }
            }
        }
        match &first {
            None => first = Some(sample),
            Some(f0) => {
                out.t.push(meas.t[s]);
                push_paper(&mut out, &l, &sample.sub(f0)); // eqs. (11), (16): differences from t₀
            }
        }
    }
    Ok(out)
}

/// Force form, Zhang 2020 eqs. (26)-(33), moments about the current base-sensor point (positions relative
/// to it, accelerations absolute). One row block per sample.
pub fn paper_force_rows(m: &Model, meas: &Measurements, base: usize, target: usize) -> Result<PaperRows> {
    let l = Layout::of(m)?;
    check_bodies(m, base, target)?;
    let n = meas.check(m)?;
    let nb = m.nvs[0];
    let known = known_parameters(m, base, target);
    let mut d = Data::new(m);
    let mut buf = Vec::with_capacity(m.nq);
    let mut y = DMatrix::zeros(m.nv, 10 * m.nbodies());
    let mut out = PaperRows::with_capacity(paper_dims(&l), n);
    for s in 0..n {
        let q = m.checked_q(&meas.q[s * m.nq..(s + 1) * m.nq], &mut buf).map_err(|e| at(e, s))?;
        let (v, a) = (&meas.v[s * m.nv..(s + 1) * m.nv], &meas.ddq[s * m.nv..(s + 1) * m.nv]);
        // the regressor runs `forward_accelerations` and leaves the body twists and accelerations in `d`
        dynamics_regressor(m, &mut d, q, v, a, &mut y).map_err(|e| at(e, s))?;
        let (p1, pn) = (PointMotion::of_body(&d, base, true), PointMotion::of_body(&d, target, true));
        let (p1s, pns) = (p1.shifted(&p1.r), pn.shifted(&p1.r));
        // base-frame wrench of the thrusters minus the known links' share (base rows of the regressor)
        let mut w = [0.0; 6];
        for r in 0..nb {
            w[r] = meas.base_wrench[s * nb + r] - row_dot(&y, r, &known);
        }
        let (f3, m3) = planar_wrench_3d(&l, &w[..nb]);
        let sample = PaperSample {
            a: pair(&g_block(&p1s), &g_block(&pns)),   // eq. (29)
            b: p1.rot * f3,                            // eq. (30)
            phi: pair(&q_block(&p1s), &q_block(&pns)), // eq. (32)
            y: p1.rot * m3,                            // eq. (33), about the base sensor
            psi: pair(&s_block(&p1s), &s_block(&pns)), // eq. (31)
        };
        out.t.push(meas.t[s]);
        push_paper(&mut out, &l, &sample);
    }
    Ok(out)
}

fn std_columns(l: &Layout, base: usize, target: usize) -> Vec<usize> {
    let c = l.std_cols();
    c.iter().map(|x| 10 * base + x).chain(c.iter().map(|x| 10 * target + x)).collect()
}

/// The standard form's momentum rows: the engine's momentum-regressor columns of base and target (standard
/// parameters about the sensor / capture point) against the impulses minus the known links' momentum,
/// cumulative differences from t₀ (Zhang 2020 eqs. (9)-(10) with the bodies in standard parameters). With
/// `meas.transport`, the angular rows are about the moving base point (`momentum_point`).
pub fn standard_momentum_rows(m: &Model, meas: &Measurements, base: usize, target: usize) -> Result<StandardRows> {
    let l = Layout::of(m)?;
    check_bodies(m, base, target)?;
    let n = meas.check(m)?;
    let known = known_parameters(m, base, target);
    let cols = std_columns(&l, base, target);
    let rows = l.momentum_rows();
    let mut d = Data::new(m);
    let mut buf = Vec::with_capacity(m.nq);
    let mut k = DMatrix::zeros(6, 10 * m.nbodies());
    let width = rows.len() * cols.len();
    let (mut phi0, mut y0) = (vec![0.0; width], vec![0.0; rows.len()]);
    let mut out = StandardRows::with_capacity([rows.len(), cols.len()], n);
    for s in 0..n {
        let q = m.checked_q(&meas.q[s * m.nq..(s + 1) * m.nq], &mut buf).map_err(|e| at(e, s))?;
        momentum_regressor(m, &mut d, q, &meas.v[s * m.nv..(s + 1) * m.nv], &mut k).map_err(|e| at(e, s))?;
        if let Some(tr) = meas.transport {
            let r_b = PointMotion::of_body(&d, base, false).r;
            let w = 3 * k.ncols();
            to_base_point(&mut k, &r_b, &tr[s * w..(s + 1) * w]);
        }
        for (i, &r) in rows.iter().enumerate() {
            let imp = if r < 3 { meas.impulse_f[3 * s + r] } else { meas.impulse_m[3 * s + r - 3] };
            let yr = imp - row_dot(&k, r, &known);
            if s == 0 {
                y0[i] = yr;
                for (j, &c) in cols.iter().enumerate() {
                    phi0[i * cols.len() + j] = k[(r, c)];
                }
            } else {
                out.y.push(yr - y0[i]);
                for (j, &c) in cols.iter().enumerate() {
                    out.phi.push(k[(r, c)] - phi0[i * cols.len() + j]);
                }
            }
        }
        if s > 0 {
            out.t.push(meas.t[s]);
        }
    }
    Ok(out)
}

/// The standard form's Newton-Euler rows: the base rows of the engine's inverse-dynamics regressor (the
/// total wrench at the base sensor, base frame) for the base and target columns, against the thruster wrench
/// minus the known links' share (Zhang 2020 eqs. (26)-(27) with the bodies in standard parameters).
pub fn standard_force_rows(m: &Model, meas: &Measurements, base: usize, target: usize) -> Result<StandardRows> {
    let l = Layout::of(m)?;
    check_bodies(m, base, target)?;
    let n = meas.check(m)?;
    let nb = m.nvs[0];
    let known = known_parameters(m, base, target);
    let cols = std_columns(&l, base, target);
    let mut d = Data::new(m);
    let mut buf = Vec::with_capacity(m.nq);
    let mut y = DMatrix::zeros(m.nv, 10 * m.nbodies());
    let mut out = StandardRows::with_capacity([nb, cols.len()], n);
    for s in 0..n {
        let q = m.checked_q(&meas.q[s * m.nq..(s + 1) * m.nq], &mut buf).map_err(|e| at(e, s))?;
        let (v, a) = (&meas.v[s * m.nv..(s + 1) * m.nv], &meas.ddq[s * m.nv..(s + 1) * m.nv]);
        dynamics_regressor(m, &mut d, q, v, a, &mut y).map_err(|e| at(e, s))?;
        for r in 0..nb {
            out.y.push(meas.base_wrench[s * nb + r] - row_dot(&y, r, &known));
            out.phi.extend(cols.iter().map(|&c| y[(r, c)]));
        }
        out.t.push(meas.t[s]);
    }
    Ok(out)
}

fn at(e: FfError, s: usize) -> FfError {
    match e {
        FfError::Argument { name, msg } => FfError::Argument { name, msg: format!("sample {s}: {msg}") },
        other => other,
    }
}

// -- parameters in each form ----------------------------------------------------------------------------

/// `(m, b', I'_c)` from standard parameters `[m, m b', I about the reference point]` (engine order):
/// `b' = h/m`, `I'_c = I_o − m (|b'|² 1 − b' b'ᵀ)` (parallel axes). A negative mass is allowed (an
/// estimator's history can pass through one); a zero mass is an error (no centre of mass).
pub fn com_form(p: &[f64]) -> Result<(f64, V3, M3)> {
    check_vec("params", p, 10)?;
    let m = p[0];
    if m == 0.0 {
        return Err(FfError::arg("params", "the mass is zero: the centre of mass is undefined"));
    }
    let h = V3::new(p[1], p[2], p[3]);
    let io = M3::new(p[4], p[5], p[7], p[5], p[6], p[8], p[7], p[8], p[9]);
    let b = h / m;
    let ic = io - (M3::identity() * b.dot(&b) - b * b.transpose()) * m;
    Ok((m, b, ic))
}

/// Standard parameters (engine order) from `(m, b', I'_c)`: `I_o = I'_c + m (|b'|² 1 − b' b'ᵀ)`.
pub fn standard_form(m: f64, b: &V3, ic: &M3) -> [f64; 10] {
    let io = ic + (M3::identity() * b.dot(b) - b * b.transpose()) * m;
    [m, m * b.x, m * b.y, m * b.z, io[(0, 0)], io[(0, 1)], io[(1, 1)], io[(0, 2)], io[(1, 2)], io[(2, 2)]]
}

/// Nearest physically consistent standard parameters in the Frobenius norm of the pseudo-inertia
/// `J = [[½ tr(I) 1 − I, h], [hᵀ, m]]` (positive definite exactly for physical bodies): eigenvalues clipped
/// at `eps · max`. A consistent set is returned unchanged.
pub fn project_consistent(p: &[f64], eps: f64) -> Result<[f64; 10]> {
    check_vec("params", p, 10)?;
    let i = M3::new(p[4], p[5], p[7], p[5], p[6], p[8], p[7], p[8], p[9]);
    let mut j = nalgebra::Matrix4::<f64>::zeros();
    j.fixed_view_mut::<3, 3>(0, 0).copy_from(&(M3::identity() * (0.5 * i.trace()) - i));
    for r in 0..3 {
        j[(r, 3)] = p[1 + r];
        j[(3, r)] = p[1 + r];
    }
    j[(3, 3)] = p[0];
    let eig = j.symmetric_eigen();
    let top = eig.eigenvalues.max().max(1e-300);
    if eig.eigenvalues.min() >= eps * top {
        // already consistent: it is its own nearest point (returned exactly, not rebuilt from the eigenvectors)
        return Ok(std::array::from_fn(|k| p[k]));
    }
    let w = eig.eigenvalues.map(|x| x.max(eps * top));
    let jp = eig.eigenvectors * nalgebra::Matrix4::from_diagonal(&w) * eig.eigenvectors.transpose();
    let s: M3 = jp.fixed_view::<3, 3>(0, 0).into_owned();
    let ip = M3::identity() * s.trace() - s;
    Ok([
        jp[(3, 3)],
        jp[(0, 3)],
        jp[(1, 3)],
        jp[(2, 3)],
        ip[(0, 0)],
        ip[(0, 1)],
        ip[(1, 1)],
        ip[(0, 2)],
        ip[(1, 2)],
        ip[(2, 2)],
    ])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spatial::{quat_exp, rot_from_quat};

    /// A smooth rigid motion of a reference point and its body: `r(t)`, `A(t) = A0 exp(φ(t))`.
    fn motion(t: f64) -> PointMotion {
        let r = |t: f64| V3::new(1.0 + 0.3 * t.sin(), -2.0 + 0.2 * t * t, 0.5 * (0.7 * t).cos());
        let rot = |t: f64| {
            let mut q0 = [0.1, -0.3, 0.2, 0.927];
            crate::spatial::quat_normalize(&mut q0);
            rot_from_quat(&q0) * rot_from_quat(&quat_exp(&V3::new(0.4 * t, -0.2 * (1.3 * t).sin(), 0.3 * t * t)))
        };
        let h = 1e-4;
        let dr = |f: &dyn Fn(f64) -> V3, t: f64| (f(t + h) - f(t - h)) / (2.0 * h);
        let w = |t: f64| {
            let rd = (rot(t + h) - rot(t - h)) / (2.0 * h);
            let wx = rd * rot(t).transpose();
            V3::new(wx[(2, 1)], wx[(0, 2)], wx[(1, 0)])
        };
        PointMotion {
            r: r(t),
            rot: rot(t),
            v: dr(&r, t),
            w: w(t),
            a: (r(t + h) - 2.0 * r(t) + r(t - h)) / (h * h),
            b: dr(&w, t),
        }
    }

    fn close(a: &V3, b: &V3, tol: f64, what: &str) {
        let s = 1.0 + a.amax().max(b.amax());
        assert!((a - b).amax() < tol * s, "{what}: {a:?} vs {b:?}");
    }

    /// Each closed form against the quantity it stands for, computed directly (the CoM c = r + A b').
    #[test]
    fn closed_forms_match_definitions() {
        let (m, bp) = (3.5, V3::new(0.2, -0.1, 0.35));
        let ic = M3::new(2.0, 0.1, -0.2, 0.1, 1.5, 0.05, -0.2, 0.05, 1.8);
        let mj = nalgebra::SVector::<f64, 10>::from_column_slice(&m_j(m, &bp));
        let mu = nalgebra::Vector4::new(m, m * bp.x, m * bp.y, m * bp.z);
        let ish = nalgebra::SVector::<f64, 6>::from_column_slice(&inertia_sharp(&ic));
        let c = |t: f64| {
            let p = motion(t);
            p.r + p.rot * bp
        };
        let h = 1e-4;
        for &t in &[0.3, 1.1, 2.7] {
            let p = motion(t);
            let cd = (c(t + h) - c(t - h)) / (2.0 * h);
            let cdd = (c(t + h) - 2.0 * c(t) + c(t - h)) / (h * h);
            let iw = p.rot * ic * p.rot.transpose();
            close(&(b_block(&p) * mu), &(cd * m), 1e-6, "B");
            close(&(g_block(&p) * mu), &(cdd * m), 1e-5, "G");
            close(&(h_block(&p) * mj), &(c(t).cross(&cd) * m), 1e-6, "H");
            close(&(s_block(&p) * mj), &(c(t).cross(&cdd) * m), 1e-5, "S");
            close(&(d_block(&p) * ish), &(iw * p.w), 1e-12, "D");
            close(&(q_block(&p) * ish), &(iw * p.b + p.w.cross(&(iw * p.w))), 1e-12, "Q");
        }
    }

    #[test]
    fn com_and_standard_forms_are_inverse() {
        let (m, b) = (2.0, V3::new(0.1, -0.4, 0.25));
        let ic = M3::new(0.5, 0.01, 0.02, 0.01, 0.7, -0.03, 0.02, -0.03, 0.6);
        let p = standard_form(m, &b, &ic);
        let (m2, b2, ic2) = com_form(&p).unwrap();
        assert!((m - m2).abs() < 1e-15 && (b - b2).amax() < 1e-15 && (ic - ic2).amax() < 1e-14);
        // a consistent body is left alone by the projection
        let pp = project_consistent(&p, 1e-9).unwrap();
        for k in 0..10 {
            assert!((pp[k] - p[k]).abs() < 1e-12, "{k}");
        }
        assert!(com_form(&[0.0; 10]).is_err());
        assert!(com_form(&[-1.0, 0.1, 0.0, 0.0, 1.0, 0.0, 1.0, 0.0, 0.0, 1.0]).is_ok());
    }
}
