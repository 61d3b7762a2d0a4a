//! One time step of the DEM: broad phase, narrow phase, forces, integration.
//!
//! Built so far: the rigid-body integrator ([`integrate`]) and the broad phase
//! ([`broad_phase`]). Every phase is written the way a GPU kernel is: a data-parallel
//! loop over particles or candidate pairs reading flat arrays and writing its own slot.

pub mod broad_phase;
pub mod integrate;
pub mod step;
pub mod time_step;
