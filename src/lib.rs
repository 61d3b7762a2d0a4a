//! talus: a polyhedral discrete element method (DEM) engine built to be stepped by
//! someone else.
//!
//! The crate is organised in layers, bottom to top (see `ARCHITECTURE.md`):
//!
//! - [`geometry`]: convex polyhedron templates, mass properties, shape generators,
//!   mesh loading, GJK, exact overlap volume, polyhedron–triangle and sphere contact
//!   kernels. It knows nothing of time, forces or scenes.
//!
//! Higher layers (contact laws, world state, engine, scene files, co-simulation and
//! transports) build on it.

pub mod geometry;

/// The scalar type used throughout talus.
pub type Real = f64;
