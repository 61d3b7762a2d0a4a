//! talus: a polyhedral discrete element method (DEM) engine built to be stepped by
//! someone else.
//!
//! The crate is organised in layers, bottom to top (see `ARCHITECTURE.md`):
//!
//! - [`geometry`]: convex polyhedron templates, mass properties, shape generators,
//!   mesh loading, GJK, exact overlap volume, polyhedron–triangle and sphere contact
//!   kernels. It knows nothing of time, forces or scenes.
//!
//! - [`contact`]: contact geometry and relative motion to forces and torques.
//! - [`fluid`]: drag laws, shape corrections and the grid of a coupled fluid.
//! - [`world`]: particles in flat arrays, body types, materials, walls with their
//!   motion, inlets, a coupled fluid's field.
//! - [`engine`]: the CPU time step (broad phase, narrow phase, accumulation,
//!   integration) and the suggested time step.
//! - [`analysis`]: figures of a use case read from a running world (the rotating
//!   drum's drive torque, angle of repose, velocity field).
//! - [`scene`]: TOML scene files, validated with errors that name file, line and
//!   field, built into a world and run as a [`scene::Simulation`].
//! - [`cosim`]: the co-simulation [`cosim::Component`] (FMI-style life cycle,
//!   variable table, communication steps, saved states).
//! - [`ffi`], [`fmi`]: the C ABI over the component (native C API; FMI 2.0 and 3.0
//!   Co-Simulation entry points and FMU packaging).
//! - `transport` (feature `zenoh`): the zenoh node over the component.
//! - [`output`]: ParaView series, CSV time series, run summary.

// `!(x > 0.0)` is how talus rejects NaN along with non-positive values; clippy's
// rewrite to `partial_cmp` would hide that intent.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod accuracy;
pub mod analysis;
pub mod checkpoint;
pub mod checksum;
pub mod contact;
pub mod cosim;
pub mod engine;
pub mod ffi;
pub mod fluid;
pub mod fmi;
pub mod geometry;
pub mod output;
pub mod recording;
pub mod scene;
#[cfg(feature = "zenoh")]
pub mod transport;
pub mod world;

/// The scalar type used throughout talus.
pub type Real = f64;

/// The talus version (the crate's), as `talus --version` and the C API report it.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");
