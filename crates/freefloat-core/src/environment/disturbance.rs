//! A constant disturbance wrench on one body (Valverde 2018, the `f_d` of (2.61)), given in inertial or in
//! body axes, acting at the body's centre of mass.

use crate::dualquat::DualQuat;
use crate::error::{FfError, Result};
use crate::spatial::{M3, V3};

/// The axes a disturbance is given in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Axes {
    /// Fixed in inertial space (e.g. solar pressure over a short run).
    Inertial,
    /// Fixed in the body (e.g. a leaking thruster).
    Body,
}

/// A constant force and torque on one body, about its centre of mass.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Disturbance {
    /// Index of the body it acts on (0: the base).
    pub body: usize,
    /// Force (N).
    pub force: V3,
    /// Torque about the body's centre of mass (N m).
    pub torque: V3,
    /// The axes `force` and `torque` are given in.
    pub axes: Axes,
}

impl Disturbance {
    /// Checks the numbers are finite and the body exists.
    pub fn check(&self, nbodies: usize) -> Result<()> {
        if let Some(k) = self.force.iter().position(|x| !x.is_finite()) {
            return Err(FfError::arg("disturbance.force", format!("entry {k} is not finite")));
        }
        if let Some(k) = self.torque.iter().position(|x| !x.is_finite()) {
            return Err(FfError::arg("disturbance.torque", format!("entry {k} is not finite")));
        }
        if self.body >= nbodies {
            return Err(FfError::arg(
                "disturbance.body",
                format!("body {} does not exist ({nbodies} bodies)", self.body),
            ));
        }
        Ok(())
    }

    /// The dual force `f + ετ` about the CoM in body axes (`rot` rotates body axes to inertial axes).
    pub fn wrench(&self, rot: &M3) -> DualQuat {
        match self.axes {
            Axes::Body => DualQuat::vector(&self.force, &self.torque),
            Axes::Inertial => DualQuat::vector(&rot.tr_mul(&self.force), &rot.tr_mul(&self.torque)),
        }
    }
}
