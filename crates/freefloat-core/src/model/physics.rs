//! Physical consistency of inertial parameters.

use crate::error::{FfError, Result};
use crate::spatial::Inertia;
use nalgebra::SymmetricEigen;

/// Relative tolerance of the positivity and triangle-inequality checks.
const TOL: f64 = 1e-9;

/// A rigid body must have mass ≥ 0 and, about its centre of mass, a symmetric positive semi-definite
/// inertia whose principal moments satisfy the triangle inequalities (each ≤ the sum of the others).
/// A massless body must have no inertia at all.
pub fn check_physical(body: &str, i: &Inertia) -> Result<()> {
    let err = |msg: String| Err(FfError::Inertia { body: body.to_string(), msg });
    if !i.mass.is_finite() || i.h.iter().chain(i.i_o.iter()).any(|x| !x.is_finite()) {
        return err("parameters are not finite".into());
    }
    if i.mass < 0.0 {
        return err(format!("mass {} is negative", i.mass));
    }
    let scale = i.i_o.abs().max().max(i.h.abs().max()).max(i.mass);
    if i.mass == 0.0 {
        if i.h.norm() > 0.0 || i.i_o.abs().max() > 0.0 {
            return err("a massless body must have zero first moment and zero inertia".into());
        }
        return Ok(());
    }
    let ic = i.i_com();
    let asym = (ic - ic.transpose()).abs().max();
    if asym > TOL * scale {
        return err("inertia matrix is not symmetric".into());
    }
    let ev = SymmetricEigen::new(ic).eigenvalues;
    let (mut l, tol) = ([ev[0], ev[1], ev[2]], TOL * scale.max(1e-300));
    l.sort_by(|a, b| a.partial_cmp(b).unwrap());
    if l[0] < -tol {
        return err(format!(
            "inertia about the centre of mass is not positive semi-definite (principal moments {:.6e}, {:.6e}, {:.6e})",
            l[0], l[1], l[2]
        ));
    }
    if l[0] + l[1] < l[2] - tol {
        return err(format!(
            "principal moments {:.6e}, {:.6e}, {:.6e} violate the triangle inequality ({:.6e} + {:.6e} < {:.6e})",
            l[0], l[1], l[2], l[0], l[1], l[2]
        ));
    }
    Ok(())
}

/// The weaker check applied to bodies whose model file allows non-physical inertia.
pub fn check_finite_nonnegative_mass(body: &str, i: &Inertia) -> Result<()> {
    if !i.mass.is_finite() || i.h.iter().chain(i.i_o.iter()).any(|x| !x.is_finite()) {
        return Err(FfError::Inertia { body: body.to_string(), msg: "parameters are not finite".into() });
    }
    if i.mass < 0.0 {
        return Err(FfError::Inertia { body: body.to_string(), msg: format!("mass {} is negative", i.mass) });
    }
    Ok(())
}
