//! Shapes and the pure geometric kernels between them.
//!
//! This layer knows nothing of time, forces or scenes. Every kernel takes shapes in
//! their body frames and the pose of one relative to the other, and answers in the
//! first shape's frame (as parry does), so that kernels stay small and testable and
//! only callers convert to world coordinates.
//!
//! Contents:
//! - [`ConvexPolyhedron`]: particle templates (merged polygon faces, outward planes,
//!   exact mass properties, principal body frame);
//! - [`generators`]: cuboids, Platonic solids, prism cylinders, icospheres, random
//!   convex particles;
//! - [`mesh_io`]: STL and OBJ loading with checks that name the offending facet;
//! - [`Polytope`]: a convex polytope cut by half-spaces, closed by construction;
//! - [`gjk`]: intersection test and separation distance;
//! - [`overlap`]: exact overlap volume, centroid and contact-area vector of two
//!   convex polyhedra;
//! - [`wall`]: polyhedron–triangle contact for wall meshes;
//! - [`sphere`]: analytic sphere kernels;
//! - [`cell_volumes`]: a particle's volume split exactly among the cells of a grid;
//! - [`section`], [`axial_volumes`]: plane sections and their areas in discs and
//!   sectors; a particle's volume in the slabs, annuli and sectors of a tube;
//! - [`voronoi_volumes`]: a particle's volume in the Voronoi cells of given centres;
//! - [`quadrature`]: Gauss–Legendre and tanh–sinh rules.

pub mod axial_volumes;
pub mod cell_volumes;
mod error;
pub mod generators;
pub mod gjk;
mod hull;
mod mass;
pub mod mesh_io;
pub mod overlap;
mod plane;
pub(crate) mod polygon;
mod polyhedron;
mod polytope;
#[cfg(test)]
mod polytope_tests;
pub mod quadrature;
mod rotation;
pub mod section;
mod shape;
mod spec;
pub mod sphere;
pub mod surfaces;
mod trimesh;
pub mod voronoi_volumes;
pub mod wall;

pub use error::GeometryError;
pub use hull::convex_hull;
pub use mass::{MassProperties, is_isotropic};
pub use plane::Plane;
pub(crate) use polygon::vector_area;
pub use polyhedron::ConvexPolyhedron;
pub use polytope::Polytope;
pub use rotation::unit_quaternion;
pub use shape::{Shape, Sphere};
pub use spec::ShapeSpec;
pub use trimesh::TriMesh;

/// Pose of a body: rotation then translation, mapping body coordinates to the
/// coordinates of the frame it lives in.
pub type Pose = nalgebra::Isometry3<crate::Real>;
