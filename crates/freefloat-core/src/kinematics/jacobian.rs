use super::{base_twist_for_momentum, base_velocity_coordinates, forward_kinematics_unchecked};
use crate::check::{check_args, check_body, check_data, check_finite, check_shape, with_unit_q, Args};
use crate::data::Data;
use crate::error::{FfError, Result};
use crate::model::Model;
use crate::spatial::{Motion, Se3};
use nalgebra::DMatrix;

/// In which axes a frame Jacobian gives the twist of the frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reference {
    /// Twist of the frame origin in the frame's own axes (Pinocchio LOCAL).
    Local,
    /// Velocity of the frame origin and angular velocity in inertial axes (Pinocchio LOCAL_WORLD_ALIGNED).
    World,
}

impl Reference {
    /// Parse `"local"` or `"world"`.
    pub fn from_name(s: &str) -> Result<Reference> {
        match s {
            "local" => Ok(Reference::Local),
            "world" => Ok(Reference::World),
            other => Err(FfError::arg("reference", format!("expected 'local' or 'world', got '{other}'"))),
        }
    }
}

/// Placement in the inertial frame of body `body` ∘ `placement` (needs forward kinematics).
pub fn frame_placement(m: &Model, d: &Data, body: usize, placement: &Se3) -> Result<Se3> {
    check_data(m, d)?;
    check_body(m, "body", body)?;
    Ok(frame_placement_unchecked(d, body, placement))
}

fn frame_placement_unchecked(d: &Data, body: usize, placement: &Se3) -> Se3 {
    d.o_mi[body].compose(placement)
}

/// Jacobian (6 × nv, into `out`) of the frame `placement` fixed on `body`: its twist is `out · v`.
/// Runs forward kinematics.
pub fn frame_jacobian(
    m: &Model,
    d: &mut Data,
    q: &[f64],
    body: usize,
    placement: &Se3,
    reference: Reference,
    out: &mut DMatrix<f64>,
) -> Result<()> {
    let fix = check_args(m, Some(d), &Args::q(q))?;
    check_body(m, "body", body)?;
    check_shape("out", out.nrows(), out.ncols(), (6, m.nv))?;
    with_unit_q(m, d, q, fix, |d, q| forward_kinematics_unchecked(m, d, q));
    jacobian_from_data(m, d, body, placement, reference, out);
    Ok(())
}

/// `frame_jacobian` from the kinematics already in `d` (forward kinematics at the q of interest has run).
pub(crate) fn jacobian_from_data(
    m: &Model,
    d: &Data,
    body: usize,
    placement: &Se3,
    reference: Reference,
    out: &mut DMatrix<f64>,
) {
    out.fill(0.0);
    let o_mf = frame_placement_unchecked(d, body, placement);
    let mut j = Some(body);
    // Only the joints on the path to the base move the frame.
    while let Some(i) = j {
        for c in 0..m.nvs[i] {
            let s = Motion::from_v6(&d.s[i].column(c).into_owned());
            let local = o_mf.inv_act_motion(&d.o_mi[i].act_motion(&s));
            let tw = match reference {
                Reference::Local => local,
                Reference::World => Motion::new(o_mf.rot * local.lin, o_mf.rot * local.ang),
            };
            let col = m.idx_v[i] + c;
            for r in 0..3 {
                out[(r, col)] = tw.lin[r];
                out[(r + 3, col)] = tw.ang[r];
            }
        }
        j = m.parents[i];
    }
}

/// Generalized Jacobian of a free-floating robot (Umetani-Yoshida): with the total momentum held at
/// `h0`, the frame twist is `Jg q̇_m + offset`, where `q̇_m` are the joint rates after the base.
/// The base velocity is eliminated through the momentum: `A_b v_b + A_m q̇_m = h0`, so
/// `Jg = J_m − J_b A_b⁻¹ A_m` and `offset = J_b A_b⁻¹ h0`. The base velocities come from the one
/// momentum solve, `base_twist_for_momentum` (column k of `−A_b⁻¹ A_m` is the base velocity of a unit
/// rate of joint k at zero momentum; `A_b⁻¹ h0` the one of the joints at rest). For a planar base only
/// the in-plane momenta (p_x, p_y, L_z) are used; for a fixed base `Jg` is the ordinary Jacobian.
/// Returns (Jg as 6 × (nv − nv_base), offset).
pub fn generalized_jacobian(
    m: &Model,
    d: &mut Data,
    q: &[f64],
    body: usize,
    placement: &Se3,
    reference: Reference,
    h0: &[f64; 6],
) -> Result<(DMatrix<f64>, [f64; 6])> {
    let fix = check_args(m, Some(d), &Args::q(q))?;
    check_body(m, "body", body)?;
    check_finite("h0", h0)?;
    let nb = m.nvs[0];
    let nm = m.nv - nb;
    let mut j = DMatrix::zeros(6, m.nv);
    if nb == 0 {
        with_unit_q(m, d, q, fix, |d, q| forward_kinematics_unchecked(m, d, q));
        jacobian_from_data(m, d, body, placement, reference, &mut j);
        return Ok((j, [0.0; 6]));
    }
    let (mut rates, mut coords) = (vec![0.0; nm], [0.0; 6]);
    let mut x = DMatrix::zeros(nb, nm);
    for k in 0..nm {
        rates[k] = 1.0;
        let tw = base_twist_for_momentum(m, d, q, &rates, &[0.0; 6])?;
        base_velocity_coordinates(m, &tw, &mut coords[..nb])?;
        x.column_mut(k).copy_from_slice(&coords[..nb]);
        rates[k] = 0.0;
    }
    let tw = base_twist_for_momentum(m, d, q, &rates, h0)?;
    base_velocity_coordinates(m, &tw, &mut coords[..nb])?;
    let y = nalgebra::DVector::from_column_slice(&coords[..nb]);
    // `d` holds the kinematics of `q` (the solves above ran them).
    jacobian_from_data(m, d, body, placement, reference, &mut j);
    let jb = j.columns(0, nb);
    let jg = j.columns(nb, nm) + jb * x;
    let off = jb * y;
    Ok((jg, [off[0], off[1], off[2], off[3], off[4], off[5]]))
}
