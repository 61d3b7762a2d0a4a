//! Shape specifications as written in scene and example files.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use serde::{Deserialize, Serialize};

use super::generators::{self, Platonic};
use super::mesh_io::{ParticleMeshOptions, load_particle};
use super::{GeometryError, Shape, Sphere};
use crate::Real;

/// How a particle shape is described in a file: a generator and its parameters, or a
/// mesh file. Lengths in metres.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum ShapeSpec {
    /// An analytic sphere.
    Sphere {
        /// Radius.
        radius: Real,
    },
    /// A box with edge lengths along x, y, z.
    Cuboid {
        /// Edge lengths.
        size: [Real; 3],
    },
    /// A Platonic solid by circumradius.
    Platonic {
        /// Which solid.
        solid: Platonic,
        /// Circumscribed radius.
        circumradius: Real,
    },
    /// An n-gon prism "cylinder" along z.
    Prism {
        /// Number of sides (20 for the pellet of Xu et al.'s packed bed).
        sides: usize,
        /// Diameter of the circumscribed circle.
        diameter: Real,
        /// Length.
        length: Real,
    },
    /// A subdivided icosahedron (20 · 4^level triangles).
    Icosphere {
        /// Subdivision level (2 gives 320 triangles).
        level: u32,
        /// Radius of the sphere it is inscribed in.
        radius: Real,
    },
    /// The hull of jittered random points on a sphere.
    RandomConvex {
        /// Number of points.
        points: usize,
        /// Sphere radius.
        radius: Real,
        /// Relative radial jitter in [0, 1).
        jitter: Real,
        /// Random seed.
        seed: u64,
    },
    /// A closed convex mesh file (STL or OBJ), relative to the file naming it.
    Mesh {
        /// Path of the mesh.
        file: PathBuf,
        /// Use the convex hull of the mesh instead of rejecting a non-convex mesh.
        #[serde(default)]
        convex_hull: bool,
        /// Factor applied to the coordinates (1e-3 for a mesh in mm).
        #[serde(default = "unit_scale")]
        scale: Real,
    },
}

fn unit_scale() -> Real {
    1.0
}

impl ShapeSpec {
    /// Builds the shape; mesh paths are taken relative to `base_dir`.
    pub fn build(&self, base_dir: &Path) -> Result<Shape, GeometryError> {
        let poly = match self {
            ShapeSpec::Sphere { radius } => return Ok(Shape::Sphere(Sphere::new(*radius)?)),
            ShapeSpec::Cuboid { size } => generators::cuboid(size[0], size[1], size[2])?,
            ShapeSpec::Platonic {
                solid,
                circumradius,
            } => generators::platonic(*solid, *circumradius)?,
            ShapeSpec::Prism {
                sides,
                diameter,
                length,
            } => generators::prism(*sides, *diameter, *length)?,
            ShapeSpec::Icosphere { level, radius } => generators::icosphere(*level, *radius)?,
            ShapeSpec::RandomConvex {
                points,
                radius,
                jitter,
                seed,
            } => generators::random_convex(*points, *radius, *jitter, *seed)?,
            ShapeSpec::Mesh {
                file,
                convex_hull,
                scale,
            } => load_particle(
                &base_dir.join(file),
                ParticleMeshOptions {
                    convex_hull: *convex_hull,
                    scale: *scale,
                },
            )?,
        };
        Ok(Shape::Polyhedron(Arc::new(poly)))
    }
}
