use super::{forward_kinematics_unchecked, forward_velocities_unchecked, world_subspace_column};
use crate::check::{check_args, check_data, with_unit_q, Args};
use crate::data::Data;
use crate::error::Result;
use crate::model::Model;
use crate::spatial::{Force, Motion};

/// Total momentum `[p; L_O]`: linear momentum and angular momentum about the inertial origin, both
/// in the inertial frame (ARCHITECTURE.md). Runs forward kinematics and velocities.
pub fn momentum(m: &Model, d: &mut Data, q: &[f64], v: &[f64]) -> Result<Force> {
    let fix = check_args(m, Some(d), &Args::qv(q, v))?;
    Ok(with_unit_q(m, d, q, fix, |d, q| {
        forward_velocities_unchecked(m, d, q, v);
        momentum_from_data_unchecked(m, d)
    }))
}

/// Total momentum (as `momentum`) from the placements and body twists already in `d` (after
/// `forward_velocities`).
pub fn momentum_from_data(m: &Model, d: &Data) -> Result<Force> {
    check_data(m, d)?;
    Ok(momentum_from_data_unchecked(m, d))
}

pub(crate) fn momentum_from_data_unchecked(m: &Model, d: &Data) -> Force {
    let mut h = Force::ZERO;
    for i in 0..m.nbodies() {
        h += d.o_mi[i].act_force(&m.inertias[i].mul_motion(&d.v[i]));
    }
    h
}

/// Kinetic energy of the whole system (J), `½ Σ vᵢᵀ Iᵢ vᵢ`.
pub fn kinetic_energy(m: &Model, d: &mut Data, q: &[f64], v: &[f64]) -> Result<f64> {
    let fix = check_args(m, Some(d), &Args::qv(q, v))?;
    Ok(with_unit_q(m, d, q, fix, |d, q| {
        forward_velocities_unchecked(m, d, q, v);
        kinetic_energy_unchecked(m, d)
    }))
}

/// Kinetic energy (J) from the body twists already in `d` (after `forward_velocities`).
pub fn kinetic_energy_from_data(m: &Model, d: &Data) -> Result<f64> {
    check_data(m, d)?;
    Ok(kinetic_energy_unchecked(m, d))
}

fn kinetic_energy_unchecked(m: &Model, d: &Data) -> f64 {
    (0..m.nbodies()).map(|i| m.inertias[i].kinetic_energy(&d.v[i])).sum()
}

/// Inertial-frame composite inertia of each body's subtree (`d.ic`) and each joint's motion
/// subspace in inertial coordinates (`d.os`), after forward kinematics. In inertial coordinates a
/// subtree's inertia is a plain sum, which is what CRBA and the momentum matrix need.
pub fn world_composite_inertias(m: &Model, d: &mut Data) -> Result<()> {
    check_data(m, d)?;
    world_composite_inertias_unchecked(m, d);
    Ok(())
}

pub(crate) fn world_composite_inertias_unchecked(m: &Model, d: &mut Data) {
    let n = m.nbodies();
    world_motion_subspaces_unchecked(m, d);
    for i in 0..n {
        d.ic[i] = m.inertias[i].transformed(&d.o_mi[i]);
    }
    for i in (1..n).rev() {
        if let Some(p) = m.parents[i] {
            let ci = d.ic[i];
            d.ic[p] = d.ic[p].add(&ci);
        }
    }
}

/// Each joint's motion subspace in inertial coordinates (`d.os`, nv columns), after forward
/// kinematics.
pub fn world_motion_subspaces(m: &Model, d: &mut Data) -> Result<()> {
    check_data(m, d)?;
    world_motion_subspaces_unchecked(m, d);
    Ok(())
}

pub(crate) fn world_motion_subspaces_unchecked(m: &Model, d: &mut Data) {
    for i in 0..m.nbodies() {
        for c in 0..m.nvs[i] {
            let s = world_subspace_column(m, d, i, c);
            d.os[i].set_column(c, &s.to_v6());
        }
    }
}

/// Centroidal momentum matrix about the inertial origin: `momentum == A v`, written into `d.jac`
/// (6 × nv). Column block j is the momentum of joint j's subtree moving rigidly with unit joint
/// rate, `oIcⱼ oSⱼ`, already about the inertial origin in inertial axes.
pub fn centroidal_momentum_matrix(m: &Model, d: &mut Data, q: &[f64]) -> Result<()> {
    let fix = check_args(m, Some(d), &Args::q(q))?;
    with_unit_q(m, d, q, fix, |d, q| centroidal_momentum_matrix_unchecked(m, d, q));
    Ok(())
}

pub(crate) fn centroidal_momentum_matrix_unchecked(m: &Model, d: &mut Data, q: &[f64]) {
    forward_kinematics_unchecked(m, d, q);
    world_composite_inertias_unchecked(m, d);
    for j in 0..m.nbodies() {
        for c in 0..m.nvs[j] {
            let h = d.ic[j].mul_motion(&Motion::from_v6(&d.os[j].column(c).into_owned()));
            let col = m.idx_v[j] + c;
            for r in 0..3 {
                d.jac[(r, col)] = h.lin[r];
                d.jac[(r + 3, col)] = h.ang[r];
            }
        }
    }
}
