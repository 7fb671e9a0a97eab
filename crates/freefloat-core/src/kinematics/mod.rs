//! Forward kinematics, centre of mass, momentum, Jacobians.

mod base_twist;
mod com;
mod fk;
mod jacobian;
mod lanes;
mod momentum;

pub use base_twist::{base_twist_for_momentum, base_velocity_coordinates};
pub use com::center_of_mass;
pub(crate) use com::center_of_mass_from_placements;
pub use fk::{classical_acceleration, forward_accelerations, forward_kinematics, forward_velocities};
pub(crate) use fk::{
    forward_accelerations_unchecked, forward_kinematics_unchecked, forward_velocities_unchecked, joint_bias,
    joint_bias_at, joint_placement_at, joint_sin_cos, joint_velocity, subspace_column_at, world_subspace_column,
};
pub(crate) use jacobian::jacobian_from_data;
pub use jacobian::{frame_jacobian, frame_placement, generalized_jacobian, Reference};
pub(crate) use lanes::{Kin, Kin4};
pub use momentum::{
    centroidal_momentum_matrix, kinetic_energy, kinetic_energy_from_data, momentum, momentum_from_data,
    world_composite_inertias, world_motion_subspaces,
};
pub(crate) use momentum::{momentum_from_data_unchecked, world_motion_subspaces_unchecked};
