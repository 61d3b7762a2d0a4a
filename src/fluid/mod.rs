//! The fluid side of CFD–DEM coupling: drag laws, shape corrections and the fluid's
//! grid. This layer knows shapes and laws, not the world: the world keeps the fluid
//! field a coupled code sets ([`crate::world::FluidField`]), the engine applies the
//! forces.

pub mod drag;
mod grid;
pub mod shape;

pub use drag::{DragLaw, FluidProperties, drag_force};
pub use grid::{FluidGrid, GridError};
pub use shape::{DragShape, ShapeCorrection};
