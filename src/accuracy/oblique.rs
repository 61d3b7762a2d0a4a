//! An oblique, eccentric corner impact against the rigid-body impulse answer.
//!
//! A particle kind, turned vertex-down and then tilted by [`TILT`] so that the
//! corner that meets the plane lies off the line of the centroid, falls at the
//! impact speed and slides sideways at half of it onto a frictionless plane. Rigid-
//! body impact theory with Newton's restitution `e` at the contact point gives the
//! answer: the impulse `J n`, `J = (1 + e) u / (1/m + (r × n) · I⁻¹ (r × n))`, turns
//! the centroid's and the angular velocity by `J n / m` and `I⁻¹ (r × J n)`. A
//! compliant contact reaches it as the contact shortens (the lever `r` turns while
//! the contact lasts), and only if its damping is calibrated on the effective mass
//! at the contact point, not on the particle's mass.

use nalgebra::{UnitQuaternion, Vector3};

use super::impacts::{Feature, aim};
use super::setup;
use crate::Real;
use crate::contact::pair_restitution;
use crate::geometry::{ConvexPolyhedron, Shape};
use crate::scene::{Scene, Simulation};

/// The tilt of the corner away from straight below the centroid, rad (25°).
pub const TILT: Real = 25.0 * std::f64::consts::PI / 180.0;

/// What one oblique corner impact realised against the rigid-body answer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ObliqueImpact {
    /// The particle kind.
    pub kind: usize,
    /// The plane's material.
    pub material: usize,
    /// `u_n' / (e u_n) − 1` at the corner that met the plane: the restitution at the
    /// contact point, realised over requested, less one.
    pub restitution_error: Real,
    /// The larger of `|v − v*|` and `|ω − ω*| R` (R the circumradius) over the
    /// impact's normal speed: how far the rebound is from the rigid-body one.
    pub impulse_error: Real,
    /// How long the contact lasted, s.
    pub contact_time: Real,
    /// The angle the rigid-body spin turns the particle by over that time, rad:
    /// rigid-body theory holds for a contact over before the particle turns (≪ 1).
    pub turn: Real,
}

/// The oblique impact of each of the scene's first polyhedral kinds (up to
/// [`super::KINDS_CHECKED`]) on its first wall material, at normal speed `speed`.
pub fn oblique_impacts(scene: &Scene, speed: Real) -> Vec<ObliqueImpact> {
    let w = &scene.world;
    w.body_types
        .iter()
        .enumerate()
        .take(super::KINDS_CHECKED)
        .filter(|(_, t)| matches!(t.shape, Shape::Polyhedron(_)))
        .map(|(kind, _)| oblique_impact(scene, kind, setup::plane_material(scene, kind), speed))
        .collect()
}

/// The body turned `down` first, then tilted by [`TILT`] about the horizontal axis
/// (of 12 tried) that leaves the most room between the lowest corner and the next:
/// the longest the impact stays a single-point one.
fn tilted(p: &ConvexPolyhedron, down: &Vector3<Real>) -> UnitQuaternion<Real> {
    let first = setup::turned_down(down);
    let room = |q: &UnitQuaternion<Real>| {
        let (mut lowest, mut next) = (Real::INFINITY, Real::INFINITY);
        for v in p.vertices() {
            let z = (q * v).z;
            if z < lowest {
                (lowest, next) = (z, lowest);
            } else if z < next {
                next = z;
            }
        }
        next - lowest
    };
    (0..12)
        .map(|k| {
            let phi = k as Real * std::f64::consts::PI / 6.0;
            let axis = nalgebra::Unit::new_normalize(Vector3::new(phi.cos(), phi.sin(), 0.0));
            UnitQuaternion::from_axis_angle(&axis, TILT) * first
        })
        .max_by(|a, b| room(a).total_cmp(&room(b)))
        .expect("twelve axes")
}

fn oblique_impact(scene: &Scene, kind: usize, material: usize, speed: Real) -> ObliqueImpact {
    let t = &scene.world.body_types[kind];
    let Shape::Polyhedron(p) = &t.shape else {
        unreachable!("oblique impacts are of polyhedra")
    };
    let (down, _) = aim(&t.shape, Feature::Vertex);
    let q = tilted(p, &down);
    let corner = *p
        .vertices()
        .iter()
        .min_by(|a, b| (q * *a).z.total_cmp(&(q * *b).z))
        .expect("a polyhedron has vertices");
    let radius = t.shape.circumradius();
    let v0 = Vector3::new(0.5 * speed, 0.0, -speed);
    let world = setup::dropped_on_plane(
        scene,
        setup::frictionless,
        t,
        q,
        material,
        0.01 * radius,
        v0,
    );
    let materials = &scene.world.materials;
    let e = pair_restitution(
        materials[t.material].restitution,
        materials[material].restitution,
    );

    // The rigid-body answer, from the pose at first touch.
    let r = q * corner.coords;
    let n = Vector3::z();
    let inverse_inertia =
        |x: Vector3<Real>| q * (q.inverse_transform_vector(&x).component_div(&t.inertia));
    let rxn = r.cross(&n);
    let inverse_mass = 1.0 / t.mass + rxn.dot(&inverse_inertia(rxn));
    let impulse = (1.0 + e) * speed / inverse_mass;
    let v_rigid = v0 + n * (impulse / t.mass);
    let w_rigid = inverse_inertia(r.cross(&(n * impulse)));

    let mut sim = Simulation::new(&scene.reference(world));
    let end = setup::contact_deadline(scene, radius, speed);
    let parted = setup::until_parted(&mut sim, end, |_| 0.0);
    let contact_time = parted.contact_steps as Real * scene.dt;
    let w = sim.world();
    let (v, omega) = (w.particles.velocity[0], w.angular_velocity(0));
    let lever = w.particles.orientation[0] * corner.coords;
    let rebound = (v + omega.cross(&lever)).z;
    ObliqueImpact {
        kind,
        material,
        restitution_error: rebound / (e * speed) - 1.0,
        impulse_error: (v - v_rigid).norm().max((omega - w_rigid).norm() * radius) / speed,
        contact_time,
        turn: w_rigid.norm() * contact_time,
    }
}
