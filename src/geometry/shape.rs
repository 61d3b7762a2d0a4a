//! The particle shape enum the engine dispatches on.

use std::f64::consts::PI;
use std::sync::Arc;

use nalgebra::Vector3;

use super::{ConvexPolyhedron, GeometryError};
use crate::Real;

/// A solid sphere: its own analytic shape, so that a scene of spheres never pays for
/// polyhedra.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// Radius.
    pub radius: Real,
}

impl Sphere {
    /// A sphere of the given radius.
    pub fn new(radius: Real) -> Result<Self, GeometryError> {
        if radius.is_finite() && radius > 0.0 {
            Ok(Sphere { radius })
        } else {
            Err(GeometryError::InvalidParameter {
                name: "radius",
                value: radius,
                reason: "must be a positive finite number",
            })
        }
    }
}

/// A particle template: a sphere or a convex polyhedron (shared between particles).
#[derive(Clone, Debug)]
pub enum Shape {
    /// Analytic sphere.
    Sphere(Sphere),
    /// Convex polyhedron in its principal body frame.
    Polyhedron(Arc<ConvexPolyhedron>),
}

impl Shape {
    /// Volume.
    pub fn volume(&self) -> Real {
        match self {
            Shape::Sphere(s) => 4.0 / 3.0 * PI * s.radius.powi(3),
            Shape::Polyhedron(p) => p.volume(),
        }
    }

    /// Surface area.
    pub fn surface_area(&self) -> Real {
        match self {
            Shape::Sphere(s) => 4.0 * PI * s.radius * s.radius,
            Shape::Polyhedron(p) => p.surface_area(),
        }
    }

    /// Principal moments of inertia per unit density.
    pub fn principal_inertia(&self) -> Vector3<Real> {
        match self {
            Shape::Sphere(s) => Vector3::repeat(0.4 * self.volume() * s.radius * s.radius),
            Shape::Polyhedron(p) => p.principal_inertia(),
        }
    }

    /// Radius of the bounding sphere about the centroid.
    pub fn circumradius(&self) -> Real {
        match self {
            Shape::Sphere(s) => s.radius,
            Shape::Polyhedron(p) => p.circumradius(),
        }
    }

    /// Radius of the sphere of equal volume.
    pub fn equivalent_radius(&self) -> Real {
        match self {
            Shape::Sphere(s) => s.radius,
            Shape::Polyhedron(p) => p.equivalent_radius(),
        }
    }

    /// The polyhedron, if this is one.
    pub fn as_polyhedron(&self) -> Option<&ConvexPolyhedron> {
        match self {
            Shape::Polyhedron(p) => Some(p),
            Shape::Sphere(_) => None,
        }
    }

    /// The sphere, if this is one.
    pub fn as_sphere(&self) -> Option<&Sphere> {
        match self {
            Shape::Sphere(s) => Some(s),
            Shape::Polyhedron(_) => None,
        }
    }
}
