//! The co-simulation component: a scene behind an FMI-style life cycle.
//!
//! A [`Component`] is what every face of talus drives: the Rust API directly, the C
//! ABI (native and FMI 2.0 / 3.0) and the zenoh node. It owns a scene's simulation,
//! its [variable table](variables), the inputs the master set (held over each
//! communication step), the outputs of the last step, and a thread pool of its own
//! (see [`pool`]).
//!
//! # Life cycle
//! ```text
//! instantiate ─► Instantiated ─enter_initialization_mode─► Initialisation
//!     ─exit_initialization_mode─► Step ─do_step…─► Step ─terminate─► Terminated
//! reset: any mode ─► Instantiated
//! ```
//! A call in the wrong mode, a non-finite input, a bad step size: an error, and the
//! component is unchanged. A step whose state blows up (a non-finite position or
//! velocity, or energy gained from nothing beyond all the scene holds: see
//! [`crate::scene::energy_balance`]) is rolled back to its start and reported.
//!
//! # Communication steps
//! `do_step(t, h)` runs DEM steps of the `dt` parameter, the last one shortened so
//! the step ends exactly at `t + h`. The mean wall force and torque are the impulse
//! over the step (trapezoidal over the DEM steps, exactly what velocity Verlet gives
//! the particles) divided by `h`, so the momentum handed across the interface is the
//! momentum the particles exchanged with the wall.

mod access;
mod component;
mod error;
pub mod pool;
mod ranks;
mod saved;
pub mod variables;

pub use component::{
    Component, ComponentState, Mode, VarRef, WallDrive, WallMeans, WallMesh, fingerprint,
};
pub use error::CosimError;
pub use variables::{Causality, Role, VarType, Variability, Variable, variable_table};
