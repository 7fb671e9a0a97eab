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
    let mut fext_power = 0.0;
    // Every per-body buffer as a slice of exactly n entries held in a register: indexing by i < n needs no bounds
    // check (through `d` each access re-reads the vector's length, which any store to a buffer might have changed).
    let (o_mi, s_all) = (&d.o_mi[..n], &d.s[..n]);
    let (os, ov, oc) = (&mut d.os[..n], &mut d.ov[..n], &mut d.oc[..n]);
    let (ias, ofs) = (&mut d.ia[..n], &mut d.of[..n]);
    let (jts, parents, idx_v, nvs, inertias) =
        (&m.joint_types[..n], &m.parents[..n], &m.idx_v[..n], &m.nvs[..n], &m.inertias[..n]);
    for i in 0..n {
        let omi = &o_mi[i];
        let iv = idx_v[i];
        // Joint twist oS q̇, specialised by joint type: a revolute joint's child-frame subspace is [0; a]
        // (oS = [p × R a; R a]) and a prismatic one's [a; 0] (oS = [R a; 0]), so neither needs the
        // general 6-column frame change; a free root's oS is the base placement's motion transform
        // itself, applied to the base twist in one step (its columns are not needed, see pass 3).
        let vj = match jts[i] {
            JointType::Revolute | JointType::Prismatic => {
                let col = subspace_column_at(m, omi, &s_all[i], i, 0);
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
        let oi = inertias[i].transformed(omi);
        ias[i] = oi.to_matrix();
        let hi = oi.mul_motion(&vi);
        if TOTALS {
            h_total += hi;
            ke += 0.5 * vi.dot(&hi);
        }
        let mut f = vi.cross_force(&hi);
        if let Some(fe) = fext {
            // the wrench in inertial coordinates, and its power on the body's twist (the simulator's work
            // integral needs it at every stage; here the frame change is already done)
            let fw = omi.act_force(&Force::from_slice(&fe[6 * i..6 * i + 6]));
            f -= fw;
            fext_power += vi.dot(&fw);
        }
        ofs[i] = f;
    }
    d.aba_fext_power = fext_power;
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
                // D positive and finite as two plain comparisons, on D and on its inverse (NaN fails the first, +∞
                // the second: 1/∞ = 0): `is_finite` compiles to ~25 integer instructions on the float's bits, per
                // body and stage (callgrind)
                let dinv = 1.0 / dd;
                if !(dd > 0.0) || !(dinv > 0.0) {
                    return Err(singular(m, d, i, v));
                }
                let uu = tau[iv] - s0.dot(&pa6);
                b.u[i].set_column(0, &V6::from(u));
                b.dinv[i][(0, 0)] = dinv;
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

/// Solve `A x = b` for a symmetric positive-definite 6×6 `A` (lower triangle read) by its 3×3 blocks,
/// `A = [P Q; Qᵀ R]`: with `W = P⁻¹ Q` and the Schur complement `S = R − Qᵀ W`, `x₂ = S⁻¹ (b₂ − Qᵀ P⁻¹ b₁)` and
/// `x₁ = P⁻¹ b₁ − W x₂`, each 3×3 inverse by its adjugate over its determinant. `None` if `A` is not numerically
/// positive definite (a leading minor of P or of S not positive: A is SPD exactly when P and S are) or the result is
/// not finite.
///
/// Why blocks and not a 6×6 Cholesky factor: the factor's six square roots and the substitutions' twelve divisions
/// form one dependent chain of about 300 cycles, ~9 % of a simulation step (perf); here two divisions and no root are
/// on the chain. The Schur complement is the one Cholesky forms implicitly after its first three columns, so the
/// cancellation in it (the angular block of an inertia far from the origin) is the same; P, the articulated linear
/// block, is about the total mass times the identity and its adjugate is exact enough.
#[inline]
fn solve_spd6(a: &M6, b: &V6) -> Option<V6> {
    let a = &a.data.0; // column-major: a[c][r] = A(r, c); lower triangle: r >= c
    let p = [a[0][0], a[0][1], a[0][2], a[1][1], a[1][2], a[2][2]];
    let (pa, pdet) = adjugate_sym3(&p)?;
    let pinv = 1.0 / pdet;
    // Q(r, c) = A(r, 3 + c) = A(3 + c, r), read from the lower triangle: q[c][r] = a[r][3 + c]
    let q: [[f64; 3]; 3] = std::array::from_fn(|c| std::array::from_fn(|r| a[r][3 + c]));
    // W = P⁻¹ Q, column by column
    let w: [[f64; 3]; 3] = std::array::from_fn(|c| mul_sym3(&pa, &q[c]).map(|x| x * pinv));
    // S = R − Qᵀ W (symmetric: six entries)
    let dot3 = |x: &[f64; 3], y: &[f64; 3]| x[0] * y[0] + x[1] * y[1] + x[2] * y[2];
    let s = [
        a[3][3] - dot3(&q[0], &w[0]),
        a[3][4] - dot3(&q[1], &w[0]),
        a[3][5] - dot3(&q[2], &w[0]),
        a[4][4] - dot3(&q[1], &w[1]),
        a[4][5] - dot3(&q[2], &w[1]),
        a[5][5] - dot3(&q[2], &w[2]),
    ];
    let (sa, sdet) = adjugate_sym3(&s)?;
    let y1 = mul_sym3(&pa, &[b[0], b[1], b[2]]).map(|x| x * pinv);
    let z = [b[3] - dot3(&q[0], &y1), b[4] - dot3(&q[1], &y1), b[5] - dot3(&q[2], &y1)];
    let x2 = mul_sym3(&sa, &z).map(|x| x / sdet);
    let x1: [f64; 3] = std::array::from_fn(|r| y1[r] - (w[0][r] * x2[0] + w[1][r] * x2[1] + w[2][r] * x2[2]));
    let x = [x1[0], x1[1], x1[2], x2[0], x2[1], x2[2]];
    x.iter().all(|v| v.is_finite()).then(|| V6::from(x))
}

/// The adjugate and the determinant of a symmetric 3×3 matrix given as `[m00, m10, m20, m11, m21, m22]` (same
/// layout out); `None` unless it is positive definite by its leading minors (m00, m00 m11 − m10², det all > 0).
#[inline(always)]
fn adjugate_sym3(m: &[f64; 6]) -> Option<([f64; 6], f64)> {
    let [m00, m10, m20, m11, m21, m22] = *m;
    let c00 = m11 * m22 - m21 * m21;
    let c10 = m21 * m20 - m10 * m22;
    let c20 = m10 * m21 - m11 * m20;
    let c11 = m00 * m22 - m20 * m20;
    let c21 = m10 * m20 - m00 * m21;
    let c22 = m00 * m11 - m10 * m10;
    let det = m00 * c00 + m10 * c10 + m20 * c20;
    (m00 > 0.0 && c22 > 0.0 && det > 0.0).then_some(([c00, c10, c20, c11, c21, c22], det))
}

/// `M x` for a symmetric 3×3 `M` in the layout of `adjugate_sym3`.
#[inline(always)]
fn mul_sym3(m: &[f64; 6], x: &[f64; 3]) -> [f64; 3] {
    [
        m[0] * x[0] + m[1] * x[1] + m[2] * x[2],
        m[1] * x[0] + m[3] * x[1] + m[4] * x[2],
        m[2] * x[0] + m[4] * x[1] + m[5] * x[2],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spatial::Inertia;
    use nalgebra::{Matrix3, Vector3};
    use rand::{Rng, SeedableRng};

    /// An articulated-inertia-like SPD matrix: the 6×6 inertias of a few random bodies about the origin, `reach` metres
    /// away, summed (as pass 2 sums a subtree's), plus the rank-one reductions of revolute joints.
    fn random_spd(rng: &mut rand::rngs::StdRng, reach: f64) -> M6 {
        let mut a = M6::zeros();
        for _ in 0..3 {
            let l = Matrix3::from_fn(|_, _| rng.gen_range(-1.0..1.0));
            let i_c = l * l.transpose() + Matrix3::identity() * 0.05;
            let com = Vector3::from_fn(|_, _| rng.gen_range(-reach..reach));
            a += Inertia::from_com(rng.gen_range(0.5..200.0), com, i_c).to_matrix();
        }
        a
    }

    /// Against nalgebra's Cholesky solve of the same system: the block solve must agree to the system's condition
    /// number times the rounding unit, on well-placed inertias and on inertias 1e3 m from the origin, whose angular
    /// block is a large cancellation (condition numbers up to ~1e12).
    #[test]
    fn block_solve_agrees_with_cholesky() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(7);
        for reach in [0.01, 1.0, 10.0, 1e3] {
            for _ in 0..200 {
                let a = random_spd(&mut rng, reach);
                let b = V6::from_fn(|_, _| rng.gen_range(-100.0..100.0));
                let x = solve_spd6(&a, &b).expect("SPD");
                let chol = a.cholesky().expect("SPD").solve(&b);
                let cond = {
                    let e = a.symmetric_eigenvalues();
                    e.max() / e.min()
                };
                let err = (x - chol).norm() / chol.norm();
                assert!(err <= 50.0 * cond * f64::EPSILON, "reach {reach}: error {err:e}, condition {cond:e}");
                // and the residual is at rounding level relative to |A| |x|, as a backward-stable solve's
                let res = (a * x - b).norm() / (a.norm() * x.norm());
                assert!(res <= 1e-13 * cond.sqrt().max(1.0), "reach {reach}: residual {res:e}");
            }
        }
    }

    /// Not positive definite: no solution (the caller reports a singular articulated inertia).
    #[test]
    fn block_solve_refuses_what_is_not_positive_definite() {
        let b = V6::from_element(1.0);
        assert!(solve_spd6(&M6::zeros(), &b).is_none());
        assert!(solve_spd6(&M6::from_diagonal(&V6::new(1.0, 1.0, 1.0, 1.0, -1.0, 1.0)), &b).is_none());
        assert!(solve_spd6(&M6::from_diagonal(&V6::new(1.0, -1.0, 1.0, 1.0, 1.0, 1.0)), &b).is_none());
        // a massless body's inertia about a point: zero linear block
        let mut a = M6::zeros();
        a.fixed_view_mut::<3, 3>(3, 3).copy_from(&Matrix3::identity());
        assert!(solve_spd6(&a, &b).is_none());
        // the identity is solved exactly
        assert_eq!(solve_spd6(&M6::identity(), &b), Some(b));
        // a NaN entry anywhere: no solution
        let mut a = M6::identity();
        a[(4, 1)] = f64::NAN;
        assert!(solve_spd6(&a, &b).is_none());
    }
}
