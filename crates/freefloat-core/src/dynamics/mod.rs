//! Recursive dynamics over the tree (Featherstone, body coordinates): RNEA, CRBA, ABA and the hybrid
//! variant of ABA in which chosen joints follow prescribed accelerations.

mod aba;
mod crba;
pub mod derivatives;
mod rnea;

pub use aba::{aba, hybrid_aba, Prescribed};
pub(crate) use aba::{hybrid_aba_placed_no_totals_unchecked, hybrid_aba_placed_unchecked, hybrid_aba_unchecked};
pub use crba::crba;
pub(crate) use crba::crba_unchecked;
pub use rnea::rnea;
pub(crate) use rnea::rnea_unchecked;

use crate::model::Model;
use crate::spatial::{Force, Motion};

/// Fictitious acceleration of the inertial frame that accounts for gravity.
#[inline]
pub(crate) fn gravity_acceleration(m: &Model) -> Motion {
    Motion::new(-m.gravity, nalgebra::Vector3::zeros())
}

/// External force on body i, body frame, or zero.
#[inline]
pub(crate) fn fext_of(fext: Option<&[f64]>, i: usize) -> Force {
    match fext {
        Some(f) => Force::from_slice(&f[6 * i..6 * i + 6]),
        None => Force::ZERO,
    }
}
