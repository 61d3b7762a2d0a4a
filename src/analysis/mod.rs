//! Figures computed from a running simulation for a use case: the rotating drum
//! (drive torque and power, angle of repose, velocity field, flowing layer, signs
//! of the flow regime) and the
//! packed bed in a tube (bed height, porosity and its profiles, coordination).
//!
//! This layer reads the [`crate::world`] and keeps its own accumulators; it never
//! changes the simulation. [`crate::output`] writes what it computes.

pub mod drum;
pub mod field;
pub mod packing;
pub mod regime;
pub mod surface;

pub use drum::{Drum, DrumMonitor, DrumRow, DrumSummary, Revolution};
pub use field::VelocityField;
pub use regime::{FlowSigns, Regime};
pub use surface::{SurfaceFit, fit_surface};
