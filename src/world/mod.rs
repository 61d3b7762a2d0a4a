//! The state of a DEM world in flat arrays: particles (structure of arrays), body
//! types (shape and material, stored once), materials, and triangulated walls.

mod inlet;
mod motion;
mod walls;

use nalgebra::{Point3, UnitQuaternion, Vector3};

pub use inlet::{Inlet, PLACEMENT_ATTEMPTS, is_free, random_orientation};
pub use motion::{DriveInput, MotionKey, WallMotion, WallVelocity, advance_pose};
pub use walls::{FacetGrid, Wall};

use crate::Real;
use crate::contact::Material;
use crate::geometry::Shape;

/// A particle template with a material: what particles of one kind share.
#[derive(Clone, Debug)]
pub struct BodyType {
    /// Shape in its principal body frame.
    pub shape: Shape,
    /// Index into [`World::materials`].
    pub material: usize,
    /// Mass.
    pub mass: Real,
    /// Principal moments of inertia.
    pub inertia: Vector3<Real>,
}

impl BodyType {
    /// A body type of `shape` made of `material` (index `material_index`).
    pub fn new(shape: Shape, material: &Material, material_index: usize) -> Self {
        BodyType {
            mass: material.density * shape.volume(),
            inertia: shape.principal_inertia() * material.density,
            shape,
            material: material_index,
        }
    }
}

/// Particle state, one entry per particle in every array.
#[derive(Clone, Debug, Default)]
pub struct Particles {
    /// Centroid positions.
    pub position: Vec<Point3<Real>>,
    /// Orientations (body frame to world).
    pub orientation: Vec<UnitQuaternion<Real>>,
    /// Linear velocities.
    pub velocity: Vec<Vector3<Real>>,
    /// Angular momenta in the world frame.
    pub angular_momentum: Vec<Vector3<Real>>,
    /// Forces of the current step.
    pub force: Vec<Vector3<Real>>,
    /// Torques about the centroid of the current step.
    pub torque: Vec<Vector3<Real>>,
    /// Index into [`World::body_types`].
    pub body_type: Vec<u32>,
    /// Stable identifier (survives reordering; keys the contact history).
    pub id: Vec<u64>,
    /// Whether the particle is frozen (see [`Particles::freeze`]): it keeps its pose,
    /// its velocity and angular momentum are zero, and only particles that are not
    /// frozen feel its contacts.
    pub frozen: Vec<bool>,
}

impl Particles {
    /// Number of particles.
    pub fn len(&self) -> usize {
        self.position.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.position.is_empty()
    }

    /// Appends a particle at rest.
    pub fn push(
        &mut self,
        body_type: u32,
        position: Point3<Real>,
        orientation: UnitQuaternion<Real>,
        id: u64,
    ) {
        self.position.push(position);
        self.orientation.push(orientation);
        self.velocity.push(Vector3::zeros());
        self.angular_momentum.push(Vector3::zeros());
        self.force.push(Vector3::zeros());
        self.torque.push(Vector3::zeros());
        self.body_type.push(body_type);
        self.id.push(id);
        self.frozen.push(false);
    }

    /// Freezes particle `i`: it stops and is no longer integrated; its contacts with
    /// other frozen particles are skipped and its wall contacts too, while a particle
    /// that is not frozen still rests on it. What a long packing run uses for the
    /// buried part of a bed, whose structure no longer changes (see `[bed] freeze`).
    pub fn freeze(&mut self, i: usize) {
        self.frozen[i] = true;
        self.velocity[i] = Vector3::zeros();
        self.angular_momentum[i] = Vector3::zeros();
    }

    /// Number of frozen particles.
    pub fn frozen_count(&self) -> usize {
        self.frozen.iter().filter(|&&f| f).count()
    }
}

/// Everything that evolves or is looked up during a step.
#[derive(Clone, Debug, Default)]
pub struct World {
    /// Materials, referred to by index.
    pub materials: Vec<Material>,
    /// Particle kinds, referred to by index.
    pub body_types: Vec<BodyType>,
    /// The particles.
    pub particles: Particles,
    /// Triangulated walls.
    pub walls: Vec<Wall>,
    /// Gravitational acceleration.
    pub gravity: Vector3<Real>,
    /// Simulated time.
    pub time: Real,
}

impl World {
    /// Angular velocity of particle `i` in the world frame.
    pub fn angular_velocity(&self, i: usize) -> Vector3<Real> {
        let p = &self.particles;
        let inertia = &self.body_types[p.body_type[i] as usize].inertia;
        if crate::engine::integrate::is_isotropic(inertia) {
            return p.angular_momentum[i] / inertia.x;
        }
        let q = p.orientation[i];
        q * q
            .inverse_transform_vector(&p.angular_momentum[i])
            .component_div(inertia)
    }

    /// Largest particle speed (translation).
    pub fn max_speed(&self) -> Real {
        self.particles
            .velocity
            .iter()
            .map(|v| v.norm())
            .fold(0.0, Real::max)
    }

    /// Gives every attached wall its leader's pose and velocities (after the leaders
    /// moved, or were set from outside). Leaders come before the walls attached to
    /// them, so one pass in order also serves chains.
    pub fn follow_leaders(&mut self) {
        for k in 0..self.walls.len() {
            if let Some(l) = self.walls[k].motion.leader() {
                let (pose, v, w) = {
                    let leader = &self.walls[l];
                    (leader.pose, leader.velocity, leader.angular_velocity)
                };
                let wall = &mut self.walls[k];
                wall.pose = pose;
                wall.velocity = v;
                wall.angular_velocity = w;
            }
        }
    }

    /// Total kinetic energy (translation and rotation).
    pub fn kinetic_energy(&self) -> Real {
        let p = &self.particles;
        (0..p.len())
            .map(|i| {
                let t = &self.body_types[p.body_type[i] as usize];
                let lb = p.orientation[i].inverse_transform_vector(&p.angular_momentum[i]);
                0.5 * t.mass * p.velocity[i].norm_squared()
                    + 0.5 * lb.dot(&lb.component_div(&t.inertia))
            })
            .sum()
    }
}
