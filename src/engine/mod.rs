//! One time step of the DEM: broad phase, narrow phase, forces, integration.
//!
//! The rigid-body integrator ([`integrate`]), the broad phase ([`broad_phase`]), the
//! Verlet lists built from it ([`neighbours`]), the contact parameters of every pair of
//! body types (`laws`), one CPU time step ([`step`], rayon) and the suggested time
//! step ([`time_step`]). Every phase is written the way a GPU
//! kernel is: a data-parallel loop over particles or candidate pairs reading flat
//! arrays and writing its own slot; each particle then gathers its pairs' forces in
//! pair order, so results do not depend on the number of threads.

pub mod broad_phase;
mod fast_hash;
pub mod integrate;
mod laws;
pub mod neighbours;
pub mod step;
pub mod time_step;
