//! The suggested time step: a fraction of the shortest contact period the scene can
//! produce.
//!
//! For every pair of body types, and every body type against every wall material,
//! the stiffest normal contact the law allows is bounded and turned into a period
//! `T = 2π √(m_eff / k)`:
//!
//! - polyhedra: the flat (face on face) contact in its regularised range has the
//!   largest stiffness, `k = κ A² / V₀^{2/3}` (see [`crate::contact::normal_force`]),
//!   with `A` the smaller of the two bodies' largest face areas;
//! - spheres (against anything): the tangent stiffness of a sphere pressed on a plane
//!   to a depth of [`SPHERE_REFERENCE_DEPTH`] of its radius (the law's stiffness grows
//!   with depth, and a contact deeper than that means the material is too soft for
//!   the scene);
//! - `m_eff` is the smallest effective mass the pair can present at a contact point:
//!   for each body `1/m + r_c² / I_min` (`r_c` the circumradius), combined in series.
//!
//! The suggested step is `T / STEPS_PER_PERIOD`. The velocity-Verlet limit for a
//! linear spring is `T / π`; at 30 steps per period the realised restitution of flat
//! and edge impacts is within 1 % of the requested one (at 20, e = 0.1 flat is 2.5 % off),
//! and within 2 % at three
//! times the suggested step (`tests/validation_restitution.rs`); the bound on
//! stiffness and mass is conservative, so the suggestion has margin.

use crate::Real;
use crate::contact::{Material, PairStiffness};
use crate::geometry::sphere::cap_volume;
use crate::geometry::{ConvexPolyhedron, Shape};
use crate::world::{BodyType, World};

/// Steps per shortest contact period in the suggested time step.
pub const STEPS_PER_PERIOD: Real = 30.0;

/// Depth, as a fraction of the sphere's radius, at which a sphere contact's stiffness
/// is evaluated.
pub const SPHERE_REFERENCE_DEPTH: Real = 0.02;

/// The suggested time step and what limits it.
#[derive(Clone, Debug, PartialEq)]
pub struct TimeStepEstimate {
    /// Suggested time step, s.
    pub dt: Real,
    /// The stiffest contact's period, s.
    pub period: Real,
    /// Which contact limits it, in words.
    pub limited_by: String,
}

/// Largest face area of a polyhedron.
pub fn largest_face_area(p: &ConvexPolyhedron) -> Real {
    (0..p.face_count())
        .map(|f| {
            let face = p.face(f);
            let v = |k: usize| p.vertices()[face[k] as usize];
            (1..face.len() - 1)
                .map(|k| (v(k) - v(0)).cross(&(v(k + 1) - v(0))))
                .sum::<nalgebra::Vector3<Real>>()
                .norm()
                * 0.5
        })
        .fold(0.0, Real::max)
}

/// The smallest effective mass body type `t` presents at any contact point.
fn smallest_effective_mass(t: &BodyType) -> Real {
    let r = t.shape.circumradius();
    1.0 / (1.0 / t.mass + r * r / t.inertia.min())
}

/// Tangent stiffness of a sphere of radius `r` on a plane at depth `δ = SPHERE_REFERENCE_DEPTH · r`
/// under the volume law with stiffness factor `kappa` and regularisation `v0`.
fn sphere_stiffness(r: Real, kappa: Real, v0: Real) -> Real {
    let force = |d: Real| {
        let v = cap_volume(r, d);
        let a = std::f64::consts::PI * (2.0 * r * d - d * d);
        if v < v0 {
            kappa * a * v / v0.powf(2.0 / 3.0)
        } else {
            kappa * a * v.cbrt()
        }
    };
    let d = SPHERE_REFERENCE_DEPTH * r;
    let h = 1e-3 * d;
    (force(d + h) - force(d - h)) / (2.0 * h)
}

/// Stiffest contact between body type `a` and a partner of shape `b` (None for a
/// wall), with stiffness factor `kappa`.
fn contact_stiffness(
    a: &Shape,
    b: Option<&Shape>,
    kappa: Real,
    regularisation_length: Real,
) -> Real {
    let r_min = b.map_or(a.equivalent_radius(), |b| {
        a.equivalent_radius().min(b.equivalent_radius())
    });
    let v0 = (regularisation_length * r_min).powi(3);
    let sphere_radius = |s: &Shape| s.as_sphere().map(|s| s.radius);
    let polyhedron_face = |s: &Shape| s.as_polyhedron().map(largest_face_area);
    match (a, b) {
        (Shape::Polyhedron(pa), None) => {
            let area = largest_face_area(pa);
            kappa * area * area / v0.powf(2.0 / 3.0)
        }
        (Shape::Polyhedron(pa), Some(b)) if b.as_polyhedron().is_some() => {
            let area = largest_face_area(pa).min(polyhedron_face(b).unwrap_or(0.0));
            kappa * area * area / v0.powf(2.0 / 3.0)
        }
        _ => {
            // A sphere is involved: the smaller sphere pressed on a plane.
            let r = [sphere_radius(a), b.and_then(sphere_radius)]
                .into_iter()
                .flatten()
                .fold(Real::INFINITY, Real::min);
            sphere_stiffness(r, kappa, v0)
        }
    }
}

/// The suggested time step for `world` (its body types and walls), with a contact
/// law regularised at `regularisation_length` times the smaller equivalent radius.
/// `None` when the world has no body types.
pub fn suggested_time_step(world: &World, regularisation_length: Real) -> Option<TimeStepEstimate> {
    let mut best: Option<TimeStepEstimate> = None;
    let mut consider = |k: Real, m: Real, what: String| {
        if !(k > 0.0 && m > 0.0) {
            return;
        }
        let period = std::f64::consts::TAU * (m / k).sqrt();
        if best.as_ref().is_none_or(|b| period < b.period) {
            best = Some(TimeStepEstimate {
                dt: period / STEPS_PER_PERIOD,
                period,
                limited_by: what,
            });
        }
    };
    let types = &world.body_types;
    let material = |t: &BodyType| -> &Material { &world.materials[t.material] };
    for (i, a) in types.iter().enumerate() {
        for (j, b) in types.iter().enumerate().skip(i) {
            let kappa = PairStiffness::particles(
                material(a),
                a.shape.equivalent_radius(),
                material(b),
                b.shape.equivalent_radius(),
            )
            .normal;
            let k = contact_stiffness(&a.shape, Some(&b.shape), kappa, regularisation_length);
            let m = 1.0 / (1.0 / smallest_effective_mass(a) + 1.0 / smallest_effective_mass(b));
            consider(k, m, format!("body types {i} and {j}"));
        }
        let mut wall_materials: Vec<usize> = world.walls.iter().map(|w| w.material).collect();
        wall_materials.sort_unstable();
        wall_materials.dedup();
        for w in wall_materials {
            let kappa = PairStiffness::particle_wall(
                material(a),
                a.shape.equivalent_radius(),
                &world.materials[w],
            )
            .normal;
            let k = contact_stiffness(&a.shape, None, kappa, regularisation_length);
            consider(
                k,
                smallest_effective_mass(a),
                format!(
                    "body type {i} on walls of material '{}'",
                    world.materials[w].name
                ),
            );
        }
    }
    best
}
