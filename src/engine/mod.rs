//! The DEM step and the seam to what computes it.
//!
//! [`Backend`] is the interface a driver steps through, with its sync contract (see
//! [`backend`]); [`CpuBackend`] (module [`cpu`], rayon) is its reference
//! implementation. Beside them: the step parameters ([`params`]), what a step hands
//! back ([`stats`]: counts, energies, time per stage), the rigid-body integrator
//! ([`integrate`]), the broad phase ([`broad_phase`]), the Verlet lists built from it
//! ([`neighbours`]), the contact parameters of every pair of body types (`laws`) and
//! the suggested time step ([`time_step`]); for a run split among ranks, the split
//! of space ([`decomposition`]), how ranks talk ([`exchange`]; measured by
//! [`metered_exchange`]) and one rank's step ([`rank`]). Every stage is written the way a GPU
//! kernel is: a data-parallel loop over particles or candidate pairs reading flat
//! arrays and writing its own slot; each particle then gathers its pairs' forces in
//! pair order, so results do not depend on the number of threads.

pub mod backend;
pub mod broad_phase;
pub mod choice;
pub mod cpu;
#[cfg(feature = "cuda")]
pub mod cuda;
pub mod decomposition;
#[cfg(test)]
mod decomposition_tests;
pub mod exchange;
mod fast_hash;
pub mod integrate;
mod laws;
pub mod metered_exchange;
#[cfg(feature = "mpi")]
pub mod mpi_exchange;
pub mod neighbours;
mod pair_sort;
pub mod params;
pub mod rank;
pub mod stats;
pub mod time_step;
pub mod wire;

pub use backend::{Backend, ContactHistory, WallKey};
pub use cpu::CpuBackend;
pub use neighbours::ListAnchors;
pub use params::{REGULARISATION_LENGTH, RoundLaw, StepParams};
pub use stats::{Stage, StageTimes, StepStats};
