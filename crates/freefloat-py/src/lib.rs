//! Python bindings of the freefloat engine (module `freefloat._core`). Only conversion and
//! validation live here; every number is computed in freefloat-core.

mod algorithms;
mod batch;
mod concurrent;
mod cpu;
mod dq;
mod dqdynamics;
mod errors;
mod estimation;
mod excitation;
mod model;
mod postcapture;
mod simulate;
mod spatial;

use pyo3::prelude::*;

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("COMPILED_CPU_FEATURES", cpu::compiled_features())?;
    m.add_class::<model::PyModel>()?;
    m.add("ModelError", py.get_type::<errors::ModelError>())?;
    m.add("InputError", py.get_type::<errors::InputError>())?;
    m.add("NumericalError", py.get_type::<errors::NumericalError>())?;
    m.add_function(wrap_pyfunction!(algorithms::forward_kinematics, m)?)?;
    m.add_function(wrap_pyfunction!(algorithms::frame_placement, m)?)?;
    m.add_function(wrap_pyfunction!(algorithms::center_of_mass, m)?)?;
    m.add_function(wrap_pyfunction!(algorithms::body_velocities, m)?)?;
    m.add_function(wrap_pyfunction!(algorithms::body_accelerations, m)?)?;
    m.add_function(wrap_pyfunction!(algorithms::momentum, m)?)?;
    m.add_function(wrap_pyfunction!(algorithms::kinetic_energy, m)?)?;
    m.add_function(wrap_pyfunction!(algorithms::centroidal_momentum_matrix, m)?)?;
    m.add_function(wrap_pyfunction!(algorithms::frame_jacobian, m)?)?;
    m.add_function(wrap_pyfunction!(algorithms::generalized_jacobian, m)?)?;
    m.add_function(wrap_pyfunction!(algorithms::momentum_regressor, m)?)?;
    m.add_function(wrap_pyfunction!(algorithms::dynamics_regressor, m)?)?;
    m.add_function(wrap_pyfunction!(algorithms::rnea, m)?)?;
    m.add_function(wrap_pyfunction!(algorithms::crba, m)?)?;
    m.add_function(wrap_pyfunction!(algorithms::aba, m)?)?;
    m.add_function(wrap_pyfunction!(algorithms::hybrid_dynamics, m)?)?;
    m.add_function(wrap_pyfunction!(simulate::simulate, m)?)?;
    m.add_function(wrap_pyfunction!(estimation::identify_momentum, m)?)?;
    m.add_function(wrap_pyfunction!(estimation::momentum_regressor_stream, m)?)?;
    m.add_function(wrap_pyfunction!(excitation::excitation_objective, m)?)?;
    m.add_function(wrap_pyfunction!(excitation::excitation_rows_py, m)?)?;
    m.add_function(wrap_pyfunction!(postcapture::postcapture_simulate, m)?)?;
    m.add_function(wrap_pyfunction!(postcapture::postcapture_rows, m)?)?;
    m.add_function(wrap_pyfunction!(postcapture::postcapture_m_j, m)?)?;
    m.add_function(wrap_pyfunction!(postcapture::inertia_com_form, m)?)?;
    m.add_function(wrap_pyfunction!(postcapture::inertia_standard_form, m)?)?;
    m.add_function(wrap_pyfunction!(postcapture::inertia_project_consistent, m)?)?;
    m.add_function(wrap_pyfunction!(spatial::quat_to_matrix, m)?)?;
    m.add_function(wrap_pyfunction!(spatial::matrix_to_quat, m)?)?;
    m.add_function(wrap_pyfunction!(spatial::skew, m)?)?;
    m.add_function(wrap_pyfunction!(spatial::integrate_base_poses, m)?)?;
    m.add_function(wrap_pyfunction!(spatial::base_twist_for_momentum, m)?)?;
    m.add_class::<postcapture::PyRls>()?;
    m.add_class::<postcapture::PyModifiedRls>()?;
    m.add_function(wrap_pyfunction!(dqdynamics::dq_dynamics, m)?)?;
    m.add_function(wrap_pyfunction!(dqdynamics::dq_condition_number, m)?)?;
    m.add_function(wrap_pyfunction!(concurrent::cl_run, m)?)?;
    m.add_function(wrap_pyfunction!(concurrent::cl_sample, m)?)?;
    m.add_function(wrap_pyfunction!(concurrent::cl_estimate, m)?)?;
    m.add_class::<concurrent::PyConcurrentEstimator>()?;
    m.add_class::<dq::PyDualQuaternion>()?;
    m.add_function(wrap_pyfunction!(dq::dq_from_pose, m)?)?;
    m.add_function(wrap_pyfunction!(dq::dq_exp, m)?)?;
    m.add_function(wrap_pyfunction!(dq::dq_screw, m)?)?;
    m.add_function(wrap_pyfunction!(dq::dq_dh, m)?)?;
    m.add_function(wrap_pyfunction!(dq::dq_dh_chain, m)?)?;
    m.add_function(wrap_pyfunction!(dq::dq_body_poses, m)?)?;
    m.add_function(wrap_pyfunction!(dq::dq_line_of_sight, m)?)?;
    m.add_function(wrap_pyfunction!(dq::dq_approach_slope, m)?)?;
    m.add_function(wrap_pyfunction!(dq::dq_attitude, m)?)?;
    m.add_function(wrap_pyfunction!(dq::dq_distance_bound, m)?)?;
    m.add_function(wrap_pyfunction!(dq::dq_r_matrix, m)?)?;
    m.add_function(wrap_pyfunction!(dq::dq_h_vector, m)?)?;
    m.add_function(wrap_pyfunction!(dq::dq_body_regressor, m)?)?;
    m.add_function(wrap_pyfunction!(dq::dq_relative_regressor, m)?)?;
    m.add_function(wrap_pyfunction!(dq::dq_inertia_params, m)?)?;
    Ok(())
}
