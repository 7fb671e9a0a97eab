//! Regressors: matrices that are exactly linear in the standard parameters, so that a quantity
//! equals `Y · vec(P)` with `P = model.parameters()` (nbodies × 10, row-major: body i owns
//! columns `10i..10i + 10`). The regressor depends on the state only, never on `P`.

mod dynamics;
mod momentum;

pub use dynamics::dynamics_regressor;
pub(crate) use momentum::{body_momentum_columns, momentum_columns_into};
pub use momentum::{momentum_regressor, momentum_regressor_from_data};

use crate::error::Result;
use crate::model::Model;
use nalgebra::{Dyn, Matrix, StorageMut};

/// Any dynamically sized matrix the regressors can write into: a `DMatrix` or a view of one,
/// e.g. a row-major view over a numpy buffer.
pub type RegressorOut<S> = Matrix<f64, Dyn, Dyn, S>;

/// The output must be `rows` × 10·nbodies.
fn check_out<S: StorageMut<f64, Dyn, Dyn>>(m: &Model, out: &RegressorOut<S>, rows: usize) -> Result<()> {
    crate::check::check_shape("out", out.nrows(), out.ncols(), (rows, 10 * m.nbodies()))
}
