//! The fluid side of CFD–DEM coupling: drag laws, shape corrections and the fluid's
//! cells (structured, cylindrical, or given by a coupled code). This layer knows
//! shapes and laws, not the world: the world keeps the fluid field a coupled code
//! sets ([`crate::world::FluidField`]), the engine applies the forces.

mod cartesian;
mod cylindrical;
pub mod drag;
mod given_cells;
mod grid;
pub mod shape;

pub use cartesian::CartesianGrid;
pub use cylindrical::CylindricalGrid;
pub use drag::{DragLaw, FluidProperties, drag_force};
pub use given_cells::GivenCells;
pub use grid::{FluidGrid, GridError, MAX_CELLS};
pub use shape::{DragShape, ShapeCorrection};
