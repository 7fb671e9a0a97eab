use super::gravity_acceleration;
use crate::check::{check_args, with_unit_q, Args};
use crate::data::Data;
use crate::error::{FfError, Result};
use crate::kinematics::{forward_kinematics_unchecked, joint_bias_at, subspace_column_at};
use crate::model::{JointType, Model};
use crate::spatial::{Force, Motion, Se3, M6, V6};
use nalgebra::Matrix3;

/// Joints whose motion is imposed: `mask[i]` for body i's joint, with accelerations taken from
/// `ddq` (length nv) at that joint's velocity indices.
#[derive(Clone, Copy)]
pub struct Prescribed<'a> {
    /// One flag per body (joint i moves body i): true if that joint's motion is prescribed.
    pub mask: &'a [bool],
    /// Accelerations (nv); only the prescribed joints' entries are read.
    pub ddq: &'a [f64],
}

/// Forward dynamics by the articulated-body algorithm: `d.ddq = M⁻¹(τ − h + Σ Jᵢᵀ fextᵢ)`.
/// Checks every argument (sizes, finiteness, unit quaternions, `d` made for `m`).
pub fn aba(m: &Model, d: &mut Data, q: &[f64], v: &[f64], tau: &[f64], fext: Option<&[f64]>) -> Result<()> {
    hybrid_aba(m, d, q, v, tau, fext, None)
}

/// Hybrid dynamics: the prescribed joints follow the given accelerations while the base and the
/// other joints respond to `tau`. On return `d.ddq` holds all accelerations and `d.tau` all joint
/// forces: `tau` for the free joints, the force each prescribed joint needed for the others.
///
/// Featherstone's articulated-body algorithm, in inertial-frame coordinates (all twists at the
/// inertial origin): inertias are expressed there once per body, so passing an articulated inertia
/// to the parent is an addition instead of a 6×6 change of frame. A prescribed joint passes its
/// whole articulated inertia to the parent together with the bias of its known acceleration.
/// Checks every argument (`presc.mask`: one flag per body, `presc.ddq`: nv).
pub fn hybrid_aba(
    m: &Model,
    d: &mut Data,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    fext: Option<&[f64]>,
    presc: Option<Prescribed>,
) -> Result<()> {
    let mut args = Args::qv(q, v).nv("tau", tau).fext(fext);
    if let Some(p) = presc {
        args = args.nv("ddq", p.ddq).mask("prescribed", p.mask);
    }
    let fix = check_args(m, Some(d), &args)?;
    with_unit_q(m, d, q, fix, |d, q| hybrid_aba_unchecked(m, d, q, v, tau, fext, presc))
}

/// `hybrid_aba` without the argument check.
pub(crate) fn hybrid_aba_unchecked(
    m: &Model,
    d: &mut Data,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    fext: Option<&[f64]>,
    presc: Option<Prescribed>,
) -> Result<()> {
    forward_kinematics_unchecked(m, d, q);
    hybrid_aba_placed_unchecked(m, d, v, tau, fext, presc)
}

/// `hybrid_aba_unchecked` after `forward_kinematics_unchecked(m, d, q)` was already run for this q (the
/// simulator's environment needs the same placements first; the pass is not repeated).
pub(crate) fn hybrid_aba_placed_unchecked(
    m: &Model,
    d: &mut Data,
    v: &[f64],
    tau: &[f64],
    fext: Option<&[f64]>,
    presc: Option<Prescribed>,
) -> Result<()> {
    hybrid_aba_placed::<true>(m, d, v, tau, fext, presc)
}

/// `hybrid_aba_placed_unchecked` without the momentum and kinetic-energy totals, which keep the values of an
/// earlier call: for the simulator's inner Runge-Kutta stages, whose states are never recorded (summing them cost
/// ~4 % of ABA, callgrind).
pub(crate) fn hybrid_aba_placed_no_totals_unchecked(
    m: &Model,
    d: &mut Data,
    v: &[f64],
    tau: &[f64],
    fext: Option<&[f64]>,
    presc: Option<Prescribed>,
) -> Result<()> {
    hybrid_aba_placed::<false>(m, d, v, tau, fext, presc)
}

/// The placed ABA; `TOTALS`: also sum the momentum and kinetic energy into `d.aba_momentum`, `d.aba_kinetic_energy`.
fn hybrid_aba_placed<const TOTALS: bool>(
    m: &Model,
    d: &mut Data,
    v: &[f64],
    tau: &[f64],
    fext: Option<&[f64]>,
    presc: Option<Prescribed>,
) -> Result<()> {
    let n = m.nbodies();
    let is_presc = |i: usize| presc.map(|p| p.mask[i]).unwrap_or(false);

    // Pass 1: subspaces, twists, velocity-product accelerations and bias forces, inertial frame.
    // Each body's momentum oIᵢ vᵢ is formed here anyway, so the totals come for free.
    let (mut h_total, mut ke) = (Force::ZERO, 0.0);
    // Every per-body buffer as a slice of exactly n entries held in a register: indexing by i < n needs no bounds
    // check (through `d` each access re-reads the vector's length, which any store to a buffer might have changed).
    let (o_mi, s_all) = (&d.o_mi[..n], &d.s[..n]);
    let (os, ov, oc) = (&mut d.os[..n], &mut d.ov[..n], &mut d.oc[..n]);
    let (ias, ofs) = (&mut d.ia[..n], &mut d.of[..n]);
    let (jts, parents, idx_v, nvs, inertias) =
        (&m.joint_types[..n], &m.parents[..n], &m.idx_v[..n], &m.nvs[..n], &m.inertias[..n]);
    for i in 0..n {
        let omi = o_mi[i];
        let iv = idx_v[i];
        // Joint twist oS q̇, specialised by joint type: a revolute joint's child-frame subspace is [0; a]
        // (oS = [p × R a; R a]) and a prismatic one's [a; 0] (oS = [R a; 0]), so neither needs the
        // general 6-column frame change; a free root's oS is the base placement's motion transform
        // itself, applied to the base twist in one step (its columns are not needed, see pass 3).
        let vj = match jts[i] {
            JointType::Revolute | JointType::Prismatic => {
                let col = subspace_column_at(m, &omi, &s_all[i], i, 0);
                os[i].set_column(0, &col.to_v6());
                col * v[iv]
            }
            JointType::Free if parents[i].is_none() && !is_presc(i) => {
                omi.act_motion(&Motion::from_slice(&v[iv..iv + 6]))
            }
            JointType::FixedBase | JointType::Fixed => Motion::ZERO,
            _ => {
                let mut vj = Motion::ZERO;
                for c in 0..nvs[i] {
                    let s = omi.act_motion(&Motion::from_v6(&s_all[i].column(c).into_owned()));
                    os[i].set_column(c, &s.to_v6());
                    vj += s * v[iv + c];
                }
                vj
            }
        };
        let vi = match parents[i] {
            Some(p) => ov[p] + vj,
            None => vj,
        };
        ov[i] = vi;
        // d/dt(oS q̇) = v × (oS q̇) + o(Ṡ q̇); the second term is non-zero for universal joints only, so the
        // others skip its frame change (measured: ~8 % of ABA on `naveen_dual_arm`).
        oc[i] = vi.cross_motion(&vj);
        if jts[i] == JointType::Universal {
            let bias = omi.act_motion(&joint_bias_at(m, &s_all[i], i, v));
            oc[i] += bias;
        }
        let oi = inertias[i].transformed(&omi);
        ias[i] = oi.to_matrix();
        let hi = oi.mul_motion(&vi);
        if TOTALS {
            h_total += hi;
            ke += 0.5 * vi.dot(&hi);
        }
        let mut f = vi.cross_force(&hi);
        if let Some(fe) = fext {
            f -= omi.act_force(&Force::from_slice(&fe[6 * i..6 * i + 6]));
        }
        ofs[i] = f;
    }
    if TOTALS {
        d.aba_momentum = h_total;
        d.aba_kinetic_energy = ke;
    }

    // Pass 2: articulated inertias and bias forces, leaves to root (the buffers as n-entry slices, see pass 1).
    let mut b = AbaBufs::of(d, n);
    for i in (0..n).rev() {
        let k = nvs[i];
        let iv = idx_v[i];
        let parent = parents[i];
        if k > 0 && !is_presc(i) {
            let s = &b.os[i];
            let pa6 = b.of[i].to_v6();
            if k == 1 {
                // Single-DoF joint: rank-one update, fused into the parent's accumulation
                // (I^a = I^A − u uᵀ/d and I^a c = I^A c − u (u·c)/d, with no 6×6 temporaries), RBDA Table 7.1.
                // Written on nalgebra's column-major arrays with fixed bounds and fused multiply-adds, U and Iᴬc in
                // one sweep and the parent's update in one loop: fewer instructions than nalgebra's 6×6 products,
                // `+=` and `ger` (callgrind).
                let s0 = s.column(0).into_owned();
                let s0a: [f64; 6] = s0.into();
                let oc: [f64; 6] = b.oc[i].to_v6().into();
                let (lo, hi) = b.ia.split_at_mut(i);
                let ia = &hi[0].data.0;
                // U = Iᴬ S and Iᴬ c in one sweep over the columns of Iᴬ
                let (u, iac) = mat6_mul2(ia, &s0a, &oc);
                let dd = dot6(&s0a, &u);
                if !(dd > 0.0) || !dd.is_finite() {
                    return Err(singular(m, d, i, v));
                }
                let uu = tau[iv] - s0.dot(&pa6);
                b.u[i].set_column(0, &V6::from(u));
                b.dinv[i][(0, 0)] = 1.0 / dd;
                b.uu[i][0] = uu;
                if let Some(p) = parent {
                    let coef = (uu - dot6(&u, &oc)) / dd;
                    let pa: [f64; 6] = std::array::from_fn(|r| pa6[r] + iac[r] + u[r] * coef);
                    let iap = &mut lo[p].data.0;
                    let alpha = -1.0 / dd;
                    for c in 0..6 {
                        let uc = u[c] * alpha;
                        for r in 0..6 {
                            iap[c][r] += u[r].mul_add(uc, ia[c][r]);
                        }
                    }
                    b.of[p] += Force::from_slice(&pa);
                }
                continue;
            }
            // Multi-DoF joint (k = 2: cylindrical; 3: spherical or planar; 6: free).
            let ia = b.ia[i];
            if k == 6 {
                // Only the base can have a free joint (the model builder enforces it), so there is no
                // reduction to pass on, and pass 3 solves the root's articulated equation in closed form.
                debug_assert!(parent.is_none(), "a 6-DoF joint is always the root");
                let _ = (ia, iv);
                continue;
            }
            // k = 2 (cylindrical) or 3 (spherical, planar base): fixed-size products.
            let ok = match k {
                2 => reduce_multi_dof::<2>(m, d, i, tau, pa6),
                3 => reduce_multi_dof::<3>(m, d, i, tau, pa6),
                _ => unreachable!("joints have 0, 1, 2, 3 or 6 velocity coordinates"),
            };
            ok?;
            // the rare multi-DoF step took `d` whole: borrow the slices again
            b = AbaBufs::of(d, n);
        } else if let Some(p) = parent {
            // Fixed or prescribed joint: the child moves with a known relative acceleration.
            let mut ac = b.oc[i].to_v6();
            if let (true, Some(pr)) = (k > 0, presc) {
                for c in 0..k {
                    ac += b.os[i].column(c) * pr.ddq[iv + c];
                }
            }
            let pa = b.of[i].to_v6() + b.ia[i] * ac;
            let ia = b.ia[i];
            b.ia[p] += ia;
            b.of[p] += Force::from_v6(&pa);
        }
    }

    // Pass 3: accelerations, root to leaves.
    let ag = gravity_acceleration(m).to_v6();
    for i in 0..n {
        let k = nvs[i];
        let iv = idx_v[i];
        let s = &b.os[i];
        let mut a = match parents[i] {
            Some(p) => b.oa[p].to_v6(),
            None => ag,
        } + b.oc[i].to_v6();
        if k == 0 {
        } else if let (true, Some(p)) = (is_presc(i), presc) {
            let ddq = p.ddq;
            for c in 0..k {
                a += s.column(c) * ddq[iv + c];
            }
            let f: V6 = b.ia[i] * a + b.of[i].to_v6();
            for c in 0..k {
                b.ddq[iv + c] = ddq[iv + c];
                b.tau[iv + c] = s.column(c).dot(&f);
            }
        } else if k == 1 {
            // Single DoF: q̈ = (u − Uᵀ a) / D, then a += oS q̈ (RBDA eq. 7.45, scalar D⁻¹).
            let (u, s0) = (&b.u[i].data.0[0], &s.data.0[0]);
            let x = b.dinv[i][(0, 0)] * (b.uu[i][0] - dot6(u, &a.data.0[0]));
            b.ddq[iv] = x;
            b.tau[iv] = tau[iv];
            a = V6::from(std::array::from_fn(|r| s0[r].mul_add(x, a[r])));
        } else {
            if parents[i].is_none() && k == 6 {
                // Free root: oS is the base placement's motion transform X₀, invertible, so the joint
                // equation τ₀ = X₀ᵀ (Iᴬ a₀ + pᴬ) gives the root acceleration from one 6×6 SPD solve,
                // Iᴬ a₀ = X₀⁻ᵀ τ₀ − pᴬ, and then q̈₀ = X₀⁻¹ (a₀ − a_g − c₀) (RBDA §7.3 with S = X₀; this
                // avoids forming U = Iᴬ X₀ and D = X₀ᵀ U, two 6×6×6 products).
                let omi = b.o_mi[i];
                let rhs0 = omi.act_force(&Force::from_slice(&tau[iv..iv + 6])) - b.of[i];
                let Some(a0) = solve_spd6(&b.ia[i], &rhs0.to_v6()) else {
                    return Err(singular(m, d, i, v));
                };
                let qdd = omi.inv_act_motion(&Motion::from_v6(&(a0 - a)));
                qdd.write(&mut b.ddq[iv..iv + 6]);
                b.tau[iv..iv + 6].copy_from_slice(&tau[iv..iv + 6]);
                b.oa[i] = Motion::from_v6(&a0);
                continue;
            }
            let mut rhs = [0.0; 6];
            for c in 0..k {
                rhs[c] = b.uu[i][c] - b.u[i].column(c).dot(&a);
            }
            if parents[i].is_none() && k > 1 {
                // Root with several DoF: d.dinv holds D itself (see pass 2).
                let Some(x) = solve_spd(&b.dinv[i], k, &rhs) else {
                    return Err(singular(m, d, i, v));
                };
                for r in 0..k {
                    b.ddq[iv + r] = x[r];
                    b.tau[iv + r] = tau[iv + r];
                    a += s.column(r) * x[r];
                }
                b.oa[i] = Motion::from_v6(&a);
                continue;
            }
            for r in 0..k {
                let x: f64 = (0..k).map(|c| b.dinv[i][(r, c)] * rhs[c]).sum();
                b.ddq[iv + r] = x;
                b.tau[iv + r] = tau[iv + r];
                a += s.column(r) * x;
            }
        }
        b.oa[i] = Motion::from_v6(&a);
    }
    Ok(())
}

/// The buffers passes 2 and 3 index, as slices of exactly n entries (ddq, tau: nv) borrowed from `Data` once:
/// local slices keep their lengths in registers, so `x[i]` with `i < n` needs no bounds check, where `d.x[i]`
/// re-reads the vector's length after every store to a buffer.
struct AbaBufs<'a> {
    o_mi: &'a [Se3],
    os: &'a [M6],
    oc: &'a [Motion],
    of: &'a mut [Force],
    oa: &'a mut [Motion],
    ia: &'a mut [M6],
    u: &'a mut [M6],
    dinv: &'a mut [M6],
    uu: &'a mut [[f64; 6]],
    ddq: &'a mut [f64],
    tau: &'a mut [f64],
}

impl<'a> AbaBufs<'a> {
    #[inline(always)]
    fn of(d: &'a mut Data, n: usize) -> Self {
        AbaBufs {
            o_mi: &d.o_mi[..n],
            os: &d.os[..n],
            oc: &d.oc[..n],
            of: &mut d.of[..n],
            oa: &mut d.oa[..n],
            ia: &mut d.ia[..n],
            u: &mut d.u[..n],
            dinv: &mut d.dinv[..n],
            uu: &mut d.uu[..n],
            ddq: &mut d.ddq[..],
            tau: &mut d.tau[..],
        }
    }
}

/// Pass-2 step of a K-DoF joint (Featherstone, RBDA §7.3, eqs. 7.43–7.45 in inertial coordinates):
/// `U = Iᴬ S`, `D = Sᵀ U`, `u = τ − Sᵀ pᴬ`; the parent receives `Iᴬ − U D⁻¹ Uᵀ` and
/// `pᴬ + Iᵃ c + U D⁻¹ u`. A multi-DoF root keeps D itself for pass 3 (nothing to pass on).
fn reduce_multi_dof<const K: usize>(m: &Model, d: &mut Data, i: usize, tau: &[f64], pa6: V6) -> Result<()> {
    let iv = m.idx_v[i];
    let ia = d.ia[i];
    let sk = d.os[i].fixed_columns::<K>(0).into_owned();
    let uk = ia * sk;
    let dm = sk.transpose() * uk;
    let uu = nalgebra::SVector::<f64, K>::from_column_slice(&tau[iv..iv + K]) - sk.transpose() * pa6;
    d.u[i] = M6::zeros();
    d.u[i].fixed_columns_mut::<K>(0).copy_from(&uk);
    d.uu[i][..K].copy_from_slice(uu.as_slice());
    d.dinv[i] = M6::zeros();
    let Some(p) = m.parents[i] else {
        d.dinv[i].fixed_view_mut::<K, K>(0, 0).copy_from(&dm);
        return Ok(());
    };
    let dinv = dm
        .cholesky()
        .map(|c| c.inverse())
        .filter(|x| x.iter().all(|v| v.is_finite()))
        .ok_or_else(|| singular(m, d, i, &[]))?;
    let ud = uk * dinv;
    let ia_a = ia - ud * uk.transpose();
    let pa = pa6 + ia_a * d.oc[i].to_v6() + ud * uu;
    d.dinv[i].fixed_view_mut::<K, K>(0, 0).copy_from(&dinv);
    d.ia[p] += ia_a;
    d.of[p] += Force::from_v6(&pa);
    Ok(())
}

/// `(A x, A y)` for a column-major 6×6 `A`, one pass over its columns.
#[inline(always)]
fn mat6_mul2(a: &[[f64; 6]; 6], x: &[f64; 6], y: &[f64; 6]) -> ([f64; 6], [f64; 6]) {
    // the first column starts the sums (no additions to zero); fused multiply-adds for the rest
    let mut ax: [f64; 6] = std::array::from_fn(|r| a[0][r] * x[0]);
    let mut ay: [f64; 6] = std::array::from_fn(|r| a[0][r] * y[0]);
    for c in 1..6 {
        for r in 0..6 {
            ax[r] = a[c][r].mul_add(x[c], ax[r]);
            ay[r] = a[c][r].mul_add(y[c], ay[r]);
        }
    }
    (ax, ay)
}

#[inline(always)]
fn dot6(a: &[f64; 6], b: &[f64; 6]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3] + a[4] * b[4] + a[5] * b[5]
}

/// The error for a joint whose articulated inertia cannot be inverted. An overflow or a NaN upstream makes it look
/// singular too (a NaN configuration reaches every frame; velocities near 1e200 square past the largest double);
/// those are reported as what they are, naming the body or the velocity entry.
fn singular(m: &Model, d: &Data, i: usize, v: &[f64]) -> FfError {
    let names = &m.body_names;
    let n = m.nbodies();
    if let Some(b) = (0..n).find(|&b| {
        let x = &d.o_mi[b];
        !(x.rot.iter().all(|a| a.is_finite()) && x.trans.iter().all(|a| a.is_finite()))
    }) {
        return FfError::Numerical(format!(
            "overflow or NaN: the placement of body '{}' is not finite (a configuration entry or a joint origin is \
             NaN or too large, e.g. 1e308)",
            names[b]
        ));
    }
    let vmax = v.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    if vmax > 1e150 {
        let k = v.iter().position(|x| x.abs() == vmax).unwrap_or(0);
        return FfError::Numerical(format!(
            "overflow: the velocity-product forces are not finite; the largest velocity entry is v[{k}] = {vmax:e} \
             (velocities above ~1e150 square past the largest double)"
        ));
    }
    if let Some(b) = (0..n).find(|&b| !d.ia[b].iter().all(|a| a.is_finite())) {
        return FfError::Numerical(format!(
            "overflow or NaN: the inertia of body '{}' in the inertial frame is not finite (its parameters or its \
             placement are too large)",
            names[b]
        ));
    }
    if (0..n).any(|b| !d.of[b].to_v6().iter().all(|a| a.is_finite())) {
        return FfError::Numerical(
            "overflow or NaN: the velocity-product or external forces are not finite (velocities, external forces or \
             inertias too large)"
                .to_string(),
        );
    }
    FfError::Numerical(format!(
        "joint '{}': its articulated inertia about the joint is singular (massless or degenerate subtree)",
        m.joint_names[i]
    ))
}

/// Solve `D x = b` for the leading k×k block (k ∈ {3, 6}) of a symmetric positive-definite D.
fn solve_spd(dm: &M6, k: usize, b: &[f64; 6]) -> Option<[f64; 6]> {
    let mut x = [0.0; 6];
    match k {
        3 => {
            let m3: Matrix3<f64> = dm.fixed_view::<3, 3>(0, 0).into_owned();
            let r = m3.cholesky()?.solve(&nalgebra::Vector3::new(b[0], b[1], b[2]));
            x[..3].copy_from_slice(r.as_slice());
        }
        6 => {
            let r = dm.cholesky()?.solve(&V6::from_column_slice(b));
            x.copy_from_slice(r.as_slice());
        }
        _ => unreachable!("a multi-DoF root has 3 or 6 velocity coordinates"),
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

/// Solve `A x = b` for a symmetric positive-definite 6×6 `A` (lower triangle read) by a Cholesky factorisation
/// `A = L Lᵀ`; `None` if `A` is not numerically positive definite or the result is not finite.
/// One const-generic step per column: every loop has a compile-time trip count and every index is a constant, so
/// the whole solve is straight-line code without bounds checks (with run-time triangular bounds the compiler kept
/// the loops and their checks: about a tenth of ABA on `naveen_dual_arm`). Same operations in the same order as
/// the textbook loops, so the same result to the bit.
#[inline]
fn solve_spd6(a: &M6, b: &V6) -> Option<V6> {
    let a = &a.data.0; // column-major: a[c][r] = A(r, c)
    let mut l = [[0.0f64; 6]; 6]; // l[i][j] = L(i, j), j <= i
    let ok = chol_col::<0>(a, &mut l)
        && chol_col::<1>(a, &mut l)
        && chol_col::<2>(a, &mut l)
        && chol_col::<3>(a, &mut l)
        && chol_col::<4>(a, &mut l)
        && chol_col::<5>(a, &mut l);
    if !ok {
        return None;
    }
    let mut y = [0.0f64; 6];
    fwd_row::<0>(&l, b, &mut y);
    fwd_row::<1>(&l, b, &mut y);
    fwd_row::<2>(&l, b, &mut y);
    fwd_row::<3>(&l, b, &mut y);
    fwd_row::<4>(&l, b, &mut y);
    fwd_row::<5>(&l, b, &mut y);
    let mut x = [0.0f64; 6];
    back_row::<5>(&l, &y, &mut x);
    back_row::<4>(&l, &y, &mut x);
    back_row::<3>(&l, &y, &mut x);
    back_row::<2>(&l, &y, &mut x);
    back_row::<1>(&l, &y, &mut x);
    back_row::<0>(&l, &y, &mut x);
    x.iter().all(|v| v.is_finite()).then(|| V6::from(x))
}

/// Column J of the Cholesky factor: `L(J,J) = √(A(J,J) − Σₖ L(J,k)²)`, `L(i,J) = (A(i,J) − Σₖ L(i,k) L(J,k)) / L(J,J)`
/// for i > J (k < J); false if the pivot is not positive.
#[inline(always)]
fn chol_col<const J: usize>(a: &[[f64; 6]; 6], l: &mut [[f64; 6]; 6]) -> bool {
    let mut djj = a[J][J];
    for k in 0..J {
        djj -= l[J][k] * l[J][k];
    }
    if !(djj > 0.0) {
        return false;
    }
    let ljj = djj.sqrt();
    l[J][J] = ljj;
    let inv = 1.0 / ljj;
    for i in J + 1..6 {
        let mut x = a[J][i];
        for k in 0..J {
            x -= l[i][k] * l[J][k];
        }
        l[i][J] = x * inv;
    }
    true
}

/// Row I of `L y = b`.
#[inline(always)]
fn fwd_row<const I: usize>(l: &[[f64; 6]; 6], b: &V6, y: &mut [f64; 6]) {
    let mut x = b[I];
    for k in 0..I {
        x -= l[I][k] * y[k];
    }
    y[I] = x / l[I][I];
}

/// Row I of `Lᵀ x = y` (rows above I already solved).
#[inline(always)]
fn back_row<const I: usize>(l: &[[f64; 6]; 6], y: &[f64; 6], x: &mut [f64; 6]) {
    let mut s = y[I];
    for k in I + 1..6 {
        s -= l[k][I] * x[k];
    }
    x[I] = s / l[I][I];
}
