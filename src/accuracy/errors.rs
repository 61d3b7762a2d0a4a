//! Every error the reference problems measure, at one setting of the knobs.

use serde::Serialize;

use super::elastic_pair::elastic_energy_error;
use super::impacts::{impact_speed, impacts};
use super::mesh_resolution::mesh_errors;
use super::oblique::oblique_impacts;
use super::resting_layer::resting_layer;
use crate::Real;
use crate::scene::Scene;

/// A quantity the reference problems measure against its exact answer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Quantity {
    /// Restitution realised over requested, face, edge and vertex first (and
    /// spheres): `impacts`.
    Restitution,
    /// The same at the contact point of an eccentric corner impact: `oblique`.
    Eccentric,
    /// Linear and angular velocity after an oblique corner impact against the
    /// rigid-body impulse answer: `oblique`.
    Impulse,
    /// Kinetic energy gained or lost by an elastic, frictionless collision:
    /// `elastic_pair`.
    ElasticEnergy,
    /// A resting layer's force on a wall against its weight: `resting_layer`.
    WallWeight,
    /// The same layer's wall force, coarse against fine triangulation.
    Triangulation,
    /// An icosphere's contact force against the analytic sphere's:
    /// `mesh_resolution`.
    MeshForce,
    /// An elastic drop of an icosphere or a prism against the curved body's.
    MeshCollision,
}

impl Quantity {
    /// Every quantity, in report order.
    pub const ALL: [Quantity; 8] = [
        Quantity::Restitution,
        Quantity::Eccentric,
        Quantity::Impulse,
        Quantity::ElasticEnergy,
        Quantity::WallWeight,
        Quantity::Triangulation,
        Quantity::MeshForce,
        Quantity::MeshCollision,
    ];

    /// The quantity's name in reports (CSV columns, JSON keys).
    pub fn name(self) -> &'static str {
        match self {
            Quantity::Restitution => "restitution",
            Quantity::Eccentric => "eccentric",
            Quantity::Impulse => "impulse",
            Quantity::ElasticEnergy => "elastic_energy",
            Quantity::WallWeight => "wall_weight",
            Quantity::Triangulation => "triangulation",
            Quantity::MeshForce => "mesh_force",
            Quantity::MeshCollision => "mesh_collision",
        }
    }
}

/// The relative error of each quantity a scene's settings produce (absolute
/// values; `None` where the scene has nothing to measure it on).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Errors([Option<Real>; Quantity::ALL.len()]);

impl Errors {
    /// Runs every reference problem of `scene` at its settings.
    pub fn measure(scene: &Scene) -> Errors {
        let speed = impact_speed(scene);
        let mut e = Errors::default();
        // The largest magnitude; a NaN (a problem that failed) wins.
        let worst = |values: &mut dyn Iterator<Item = Real>| {
            values.map(Real::abs).fold(None, |w: Option<Real>, x| {
                Some(match w {
                    Some(w) if w.is_nan() || x.is_nan() => Real::NAN,
                    Some(w) => w.max(x),
                    None => x,
                })
            })
        };
        let hits = impacts(scene, speed);
        e.set(
            Quantity::Restitution,
            worst(&mut hits.iter().map(|i| i.restitution_error())),
        );
        let oblique = oblique_impacts(scene, speed);
        e.set(
            Quantity::Eccentric,
            worst(&mut oblique.iter().map(|o| o.restitution_error)),
        );
        e.set(
            Quantity::Impulse,
            worst(&mut oblique.iter().map(|o| o.impulse_error)),
        );
        if !scene.world.body_types.is_empty() {
            e.set(
                Quantity::ElasticEnergy,
                Some(elastic_energy_error(scene, speed).abs()),
            );
        }
        if let Some(layer) = resting_layer(scene) {
            e.set(Quantity::WallWeight, Some(layer.weight_error.abs()));
            e.set(Quantity::Triangulation, Some(layer.triangulation_error));
        }
        let mesh = mesh_errors(scene, speed);
        e.set(Quantity::MeshForce, mesh.force);
        e.set(Quantity::MeshCollision, mesh.collision);
        e
    }

    /// The error of `q`, if measured.
    pub fn get(&self, q: Quantity) -> Option<Real> {
        self.0[q as usize]
    }

    /// Sets the error of `q`.
    pub fn set(&mut self, q: Quantity, error: Option<Real>) {
        self.0[q as usize] = error;
    }

    /// The measured quantities and their errors, in report order.
    pub fn iter(&self) -> impl Iterator<Item = (Quantity, Real)> + '_ {
        Quantity::ALL
            .iter()
            .filter_map(|&q| self.get(q).map(|e| (q, e)))
    }

    /// The largest error (NaN, a failed problem, counts as infinite); 0 when
    /// nothing was measured.
    pub fn worst(&self) -> Real {
        self.iter()
            .map(|(_, e)| if e.is_nan() { Real::INFINITY } else { e })
            .fold(0.0, Real::max)
    }
}
