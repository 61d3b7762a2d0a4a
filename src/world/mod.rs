//! The state of a DEM world in flat arrays: particles (structure of arrays), body
//! types (shape and material, stored once), materials, and triangulated walls.

mod cell_shares;
mod figures;
mod fluid;
mod inlet;
mod motion;
mod particles;
mod space_order;
mod walls;

use std::ops::Range;

use nalgebra::Vector3;

pub use cell_shares::{CellShares, ShareRow};
pub use figures::RunFigures;
pub use fluid::{
    CellContribution, DragModel, FluidField, LocalFluid, MomentumExchange, ParticleFluid,
};
pub use inlet::{Inlet, Obstacle, PLACEMENT_ATTEMPTS, PlacedParticle, is_free, random_orientation};
pub use motion::{DriveInput, MotionKey, WallMotion, WallVelocity, advance_pose};
pub use particles::Particles;
pub(crate) use particles::all_finite_entries;
pub use space_order::SpaceOrder;

/// The mass of a set of particles and its first moment `Σ m x`: the moment of
/// their weight about any point (a sum, so the shares of ranks add up).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MassMoments {
    /// Σ m, kg.
    pub mass: Real,
    /// Σ m x, kg m.
    pub first: Vector3<Real>,
}
pub use walls::{FacetGrid, Wall};

use crate::Real;
use crate::contact::Material;
use crate::geometry::{Shape, is_isotropic};

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
    /// The fluid of a CFD-coupled scene.
    pub fluid: Option<FluidField>,
}

impl World {
    /// Angular velocity of particle `i` in the world frame.
    pub fn angular_velocity(&self, i: usize) -> Vector3<Real> {
        let p = &self.particles;
        let inertia = &self.body_types[p.body_type[i] as usize].inertia;
        if is_isotropic(inertia) {
            return p.angular_momentum[i] / inertia.x;
        }
        let q = p.orientation[i];
        q * q
            .inverse_transform_vector(&p.angular_momentum[i])
            .component_div(inertia)
    }

    /// Largest speed (translation) of the owned particles.
    pub fn max_speed(&self) -> Real {
        self.particles.velocity[..self.particles.owned()]
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

    /// Sets the force of particles `range` to their weight and their torque to
    /// zero: what a particle just inserted feels in its first half kick.
    pub fn weigh(&mut self, range: Range<usize>) {
        let p = &mut self.particles;
        for i in range {
            p.force[i] = self.gravity * self.body_types[p.body_type[i] as usize].mass;
            p.torque[i] = Vector3::zeros();
        }
    }

    /// The mass of the owned particles and its first moment.
    pub fn mass_moments(&self) -> MassMoments {
        let p = &self.particles;
        let mut m = MassMoments::default();
        for i in 0..p.owned() {
            let mass = self.body_types[p.body_type[i] as usize].mass;
            m.mass += mass;
            m.first += p.position[i].coords * mass;
        }
        m
    }

    /// Total kinetic energy (translation and rotation) of the owned particles.
    pub fn kinetic_energy(&self) -> Real {
        (0..self.particles.owned())
            .map(|i| self.particle_kinetic_energy(i))
            .sum()
    }

    /// Kinetic energy of particle `i`: translation and rotation (about its principal
    /// axes, from the angular momentum).
    pub fn particle_kinetic_energy(&self, i: usize) -> Real {
        let p = &self.particles;
        let t = &self.body_types[p.body_type[i] as usize];
        let lb = p.orientation[i].inverse_transform_vector(&p.angular_momentum[i]);
        0.5 * t.mass * p.velocity[i].norm_squared() + 0.5 * lb.dot(&lb.component_div(&t.inertia))
    }
}
