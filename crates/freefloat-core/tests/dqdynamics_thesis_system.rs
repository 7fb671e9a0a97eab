//! Valverde 2018's own system ((6.17)–(6.27)) assembled literally in 8-vector form — 8×8 product
//! matrices, the E-selectors of Tables 6.2/6.3 in the thesis' slot order (not our symmetric variant), the
//! zero scalar slots kept — and solved with a dense LU of the full (8B + R)-square matrix. Its accelerations
//! and joint wrenches must equal `dq_dynamics` (symmetric variant, 6-vectors, tree elimination). Geometry and
//! twists come from the engine's FK and velocities, not from `dqdynamics`.

mod common;

use common::{random_model, random_q, random_vec, rel_err, rng};
use freefloat_core::data::Data;
use freefloat_core::dqdynamics::dq_dynamics;
use freefloat_core::dqdynamics::joints::{alignment, universal_alignment, universal_frame_rate};
use freefloat_core::dualquat::pose::{translation, twist_from_motion};
use freefloat_core::dualquat::{DualInertia, DualQuat, M8};
use freefloat_core::kinematics::forward_velocities;
use freefloat_core::model::JointType;
use nalgebra::{DMatrix, DVector};

/// Kept slots (0-based in the 8-vector) of V_j (wrench) and Λ_j (twist), thesis Table 6.2, and the actuated
/// wrench slots of Table 6.3.
fn thesis_slots(kind: JointType) -> (Vec<usize>, Vec<usize>, Vec<usize>) {
    match kind {
        JointType::Revolute => (vec![1, 2, 3, 5, 6], vec![1, 2, 5, 6, 7], vec![7]), // V = E158ᵀ, Λ = E145
        JointType::Prismatic => (vec![1, 2, 5, 6, 7], vec![1, 2, 3, 5, 6], vec![3]), // V = E145ᵀ, Λ = E158
        JointType::Spherical => (vec![1, 2, 3], vec![5, 6, 7], vec![5, 6, 7]),      // V = E15678ᵀ, Λ = E12345
        // cylindrical (not in Table 6.2): the revolute and prismatic reactions intersected; q = [θ, d]
        JointType::Cylindrical => (vec![1, 2, 5, 6], vec![1, 2, 5, 6], vec![7, 3]),
        // universal (not in Table 6.2), in its turning joint frame: reaction f and τ_z, free ω_x, ω_y
        JointType::Universal => (vec![1, 2, 3, 7], vec![3, 5, 6, 7], vec![5, 6]),
        _ => (vec![1, 2, 3, 5, 6, 7], vec![1, 2, 3, 5, 6, 7], vec![]),
    }
}

fn select_cols(m: &M8, cols: &[usize]) -> DMatrix<f64> {
    DMatrix::from_fn(8, cols.len(), |r, c| m[(r, cols[c])])
}
fn select_rows(m: &M8, rows: &[usize]) -> DMatrix<f64> {
    DMatrix::from_fn(rows.len(), 8, |r, c| m[(rows[r], c)])
}

#[test]
fn literal_thesis_system_equals_dq_dynamics() {
    let mut r = rng(606);
    for case in 0..30 {
        let m = random_model(&mut r, JointType::Free, 2 + case % 8, false);
        let n = m.nbodies();
        let q = random_q(&m, &mut r);
        let v = random_vec(m.nv, &mut r);
        let tau = random_vec(m.nv, &mut r);
        let mut d = Data::new(&m);
        forward_velocities(&m, &mut d, &q, &v).unwrap();
        let com: Vec<_> = m.inertias.iter().map(|i| i.com()).collect();
        let to_com: Vec<DualQuat> = com.iter().map(translation).collect();
        // CoM twists (8-vectors): ω^{o_i} = q*_{o/B} ω^B q_{o/B}
        let w: Vec<DualQuat> = (0..n).map(|i| to_com[i].shift_in(&twist_from_motion(&d.v[i]))).collect();
        let mi: Vec<DualInertia> = m.inertias.iter().map(|x| DualInertia::from_inertia(x).expect("physical")).collect();
        // joints: (child i, parent k, q_{j/o_k}, q_{o_i/j}, V, Λ, act slots, offset)
        let mut js = Vec::new();
        let mut rr = 0;
        for i in 1..n {
            let k = m.parents[i].expect("tree");
            let (al, rho) = if m.joint_types[i] == JointType::Universal {
                let (iq, iv) = (m.idx_q[i], m.idx_v[i]);
                let r6 = universal_frame_rate(v[iv + 1]);
                let rho = DualQuat::vector(&nalgebra::Vector3::new(r6[0], r6[1], r6[2]), &nalgebra::Vector3::zeros());
                (universal_alignment(&m.axes[i], &m.axes2[i], q[iq + 1]), rho)
            } else {
                (alignment(m.joint_types[i], &m.axes[i]), DualQuat::ZERO)
            };
            let q_jo = to_com[k].conj().mul(&DualQuat::from_se3(&d.li_mi[i])).mul(&al);
            let q_oj = al.conj().mul(&to_com[i]);
            let (vs, ls, acts) = thesis_slots(m.joint_types[i]);
            let len = vs.len();
            js.push((i, k, q_jo, q_oj, vs, ls, acts, rr, al, rho));
            rr += len;
        }
        let size = 8 * n + rr;
        let mut s = DMatrix::zeros(size, size);
        let mut b = DVector::zeros(size);
        for i in 0..n {
            s.view_mut((8 * i, 8 * i), (8, 8)).copy_from(&mi[i].swapped_matrix()); // (6.18)
            let b1 = -w[i].cross(&mi[i].momentum(&w[i])); // (6.22), no gravity or external wrench here
            b.rows_mut(8 * i, 8).copy_from(&b1.to_vec8());
        }
        // free-base actuation at the base origin
        let wb = to_com[0].shift_in(&DualQuat::vector(
            &nalgebra::Vector3::new(tau[0], tau[1], tau[2]),
            &nalgebra::Vector3::new(tau[3], tau[4], tau[5]),
        ));
        let mut b0 = b.rows(0, 8).clone_owned();
        b0 += wb.to_vec8();
        b.rows_mut(0, 8).copy_from(&b0);
        for (i, k, q_jo, q_oj, vs, ls, acts, off, _, rho) in &js {
            let (i, k, off) = (*i, *k, *off);
            // (6.20): S12
            let dist = -(q_oj.conj().left_matrix() * q_oj.right_matrix());
            let prox = q_jo.left_matrix() * q_jo.conj().right_matrix();
            s.view_mut((8 * i, 8 * n + off), (8, vs.len())).copy_from(&select_cols(&dist, vs));
            s.view_mut((8 * k, 8 * n + off), (8, vs.len())).copy_from(&select_cols(&prox, vs));
            // (6.21): S21
            let dist21 = q_oj.left_matrix() * q_oj.conj().right_matrix();
            let prox21 = -(q_jo.conj().left_matrix() * q_jo.right_matrix());
            s.view_mut((8 * n + off, 8 * i), (ls.len(), 8)).copy_from(&select_rows(&dist21, ls));
            s.view_mut((8 * n + off, 8 * k), (ls.len(), 8)).copy_from(&select_rows(&prox21, ls));
            // (6.23): B2 = Λ (q* ω_k q) × ω^j, with ω^j from (6.13)
            let wk_j = q_jo.shift_in(&w[k]);
            let wj = q_oj.shift_out(&w[i]) - wk_j;
            // a turning joint frame (universal) adds its rate ρ to the parent twist (see dqdynamics::system)
            let c = (wk_j + *rho).cross(&wj).to_vec8();
            for (row, &sl) in ls.iter().enumerate() {
                b[8 * n + off + row] = c[sl];
            }
            // actuation into (6.22)
            let mut wa = nalgebra::SVector::<f64, 8>::zeros();
            for (c, &sl) in acts.iter().enumerate() {
                wa[sl] = tau[m.idx_v[i] + c];
            }
            let wa = DualQuat::from_vec8(&wa);
            let add_i = q_oj.shift_in(&wa).to_vec8();
            let sub_k = q_jo.shift_out(&wa).to_vec8();
            let mut bi = b.rows(8 * i, 8).clone_owned();
            bi += add_i;
            b.rows_mut(8 * i, 8).copy_from(&bi);
            let mut bk = b.rows(8 * k, 8).clone_owned();
            bk -= sub_k;
            b.rows_mut(8 * k, 8).copy_from(&bk);
        }
        // the condition number of the thesis' matrix (Figs. 5.5, 7.x) from the library equals this one's
        let sv = s.clone().singular_values();
        let cond = sv.max() / sv.min();
        let lib = freefloat_core::dqdynamics::condition_number(&m, &q).expect("condition");
        assert!((lib - cond).abs() < 1e-8 * cond, "case {case}: {lib} vs {cond}");
        let y = s.clone().lu().solve(&b).expect("full system is nonsingular");
        assert!((&s * &y - &b).amax() < 1e-9 * (1.0 + b.amax()));
        let res = dq_dynamics(&m, &mut Data::new(&m), &q, &v, &tau, None, None).cloned().expect("dq");
        // base: ẏ_0 = [0, ω̇, 0, v̇_o] → [v̇_b; ω̇]
        let wd = nalgebra::Vector3::new(y[1], y[2], y[3]);
        let vo = nalgebra::Vector3::new(y[5], y[6], y[7]);
        let vb = vo - wd.cross(&com[0]);
        let base = [vb.x, vb.y, vb.z, wd.x, wd.y, wd.z];
        assert!(rel_err(&res.ddq[0..6], &base) < 1e-10, "case {case}");
        for (i, _k, _q_jo, _q_oj, vs, _ls, acts, off, al, _) in &js {
            let mut wj = nalgebra::SVector::<f64, 8>::zeros();
            for (c, &sl) in vs.iter().enumerate() {
                wj[sl] = y[8 * n + off + c];
            }
            for (c, &sl) in acts.iter().enumerate() {
                wj[sl] = tau[m.idx_v[*i] + c];
            }
            let wb = al.shift_out(&DualQuat::from_vec8(&wj)); // J → child body frame
            let got = res.joint_wrenches[*i].to_v6();
            let expect = [wb.r.v.x, wb.r.v.y, wb.r.v.z, wb.d.v.x, wb.d.v.y, wb.d.v.z];
            assert!(rel_err(got.as_slice(), &expect) < 1e-9, "case {case} joint {i}");
        }
    }
}
