//! What a curved particle given as a mesh loses against the curved body: the
//! mesh-resolution study of the PolyDEM paper, on the user's icospheres and prisms.
//!
//! - Contact force (icospheres): the mesh at random orientations, pressed into a
//!   plane as deep as the analytic sphere goes in the scene's impact, against the
//!   analytic sphere at that depth under the same (volume) law. An icosphere's
//!   sagitta falls fourfold per level; so does this error once the sagitta is small
//!   against the depth.
//! - Collision outcome (icospheres and prisms lying on their side): an elastic,
//!   frictionless drop at random orientations. The curved body rebounds straight, at
//!   the speed it came, without spin; the mesh's facet normals miss the centroid
//!   and turn part of the impact into spin and sideways motion.

use nalgebra::{Point3, UnitQuaternion, Vector3};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

use super::setup;
use crate::Real;
use crate::geometry::{Shape, ShapeSpec, Sphere};
use crate::scene::spec::ContactLawSpec;
use crate::scene::{Scene, Simulation};
use crate::world::{BodyType, World, random_orientation};

/// Random orientations per kind.
pub const ORIENTATIONS: usize = 6;

/// The mesh errors of a scene's icosphere and prism kinds (worst over kinds);
/// `None` where it has none.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MeshErrors {
    /// RMS over orientations of `F_mesh / F_sphere − 1` at the same depth.
    pub force: Option<Real>,
    /// The largest of `| |v'|/u − 1 |`, the sideways rebound `|v'_t|/u` and the spin
    /// `|ω'| R / u` over orientations.
    pub collision: Option<Real>,
}

/// The curved body a kind's mesh stands for.
enum Curved {
    Sphere { radius: Real },
    Cylinder,
}

/// The mesh errors of `scene`'s first kinds (up to [`super::KINDS_CHECKED`]) at
/// impact speed `speed`.
pub fn mesh_errors(scene: &Scene, speed: Real) -> MeshErrors {
    let mut out = MeshErrors::default();
    let worst = |a: Option<Real>, b: Real| Some(a.map_or(b, |a: Real| a.max(b)));
    for kind in 0..scene.world.body_types.len().min(super::KINDS_CHECKED) {
        let spec = scene
            .shape_names
            .get(kind)
            .and_then(|name| scene.spec.shapes.get(name));
        let curved = match spec {
            Some(ShapeSpec::Icosphere { radius, .. }) => Curved::Sphere { radius: *radius },
            Some(ShapeSpec::Prism { .. }) => Curved::Cylinder,
            _ => continue,
        };
        if let Curved::Sphere { radius } = curved {
            out.force = worst(out.force, force_error(scene, kind, radius, speed));
        }
        out.collision = worst(out.collision, collision_error(scene, kind, &curved, speed));
    }
    out
}

/// A scene holding `world` whose round contacts follow the volume law, as the
/// mesh's do.
fn volume_law(scene: &Scene, world: World) -> Scene {
    let mut s = scene.reference(world);
    s.spec.contact.law = ContactLawSpec::Volume;
    s.spec.contact.rolling = crate::contact::RollingModel::None;
    s
}

fn force_error(scene: &Scene, kind: usize, radius: Real, speed: Real) -> Real {
    let t = &scene.world.body_types[kind];
    let material = setup::plane_material(scene, kind);
    let sphere = BodyType::new(
        Shape::Sphere(Sphere::new(radius).expect("an icosphere's radius is positive")),
        &scene.world.materials[t.material],
        t.material,
    );
    // How deep the analytic sphere goes in the scene's impact.
    let mut world = setup::world(
        scene,
        |_| {},
        vec![sphere.clone()],
        vec![setup::plane(material, radius)],
    );
    world.particles.push(
        0,
        Point3::new(0.0, 0.0, 1.01 * radius),
        UnitQuaternion::identity(),
        0,
    );
    world.particles.velocity[0] = Vector3::new(0.0, 0.0, -speed);
    let mut sim = Simulation::new(&volume_law(scene, world));
    let end = setup::contact_deadline(scene, radius, speed);
    let depth = setup::until_parted(&mut sim, end, |w| radius - w.particles.position[0].z).deepest;

    let pressed = |t: &BodyType, q: UnitQuaternion<Real>| {
        let mut world = setup::world(
            scene,
            |_| {},
            vec![t.clone()],
            vec![setup::plane(material, radius)],
        );
        world
            .particles
            .push(0, Point3::new(0.0, 0.0, radius - depth), q, 0);
        let mut sim = Simulation::new(&volume_law(scene, world));
        sim.initialise();
        -sim.world().walls[0].force.z
    };
    let exact = pressed(&sphere, UnitQuaternion::identity());
    let mut rng = Pcg64::seed_from_u64(80);
    let sum: Real = (0..ORIENTATIONS)
        .map(|_| (pressed(t, random_orientation(&mut rng)) / exact - 1.0).powi(2))
        .sum();
    (sum / ORIENTATIONS as Real).sqrt()
}

fn collision_error(scene: &Scene, kind: usize, curved: &Curved, speed: Real) -> Real {
    let t = &scene.world.body_types[kind];
    let material = setup::plane_material(scene, kind);
    let r = t.shape.circumradius();
    let mut rng = Pcg64::seed_from_u64(20_480);
    let mut worst: Real = 0.0;
    for _ in 0..ORIENTATIONS {
        let q = match curved {
            Curved::Sphere { .. } => random_orientation(&mut rng),
            // The axis (body z) along x, rolled at random about it.
            Curved::Cylinder => {
                let roll = rng.random_range(0.0..std::f64::consts::TAU);
                UnitQuaternion::from_axis_angle(&Vector3::x_axis(), roll)
                    * UnitQuaternion::from_axis_angle(
                        &Vector3::y_axis(),
                        std::f64::consts::FRAC_PI_2,
                    )
            }
        };
        let world = setup::dropped_on_plane(
            scene,
            setup::elastic,
            t,
            q,
            material,
            0.01 * r,
            Vector3::new(0.0, 0.0, -speed),
        );
        let mut sim = Simulation::new(&volume_law(scene, world));
        let parted =
            setup::until_parted(&mut sim, setup::contact_deadline(scene, r, speed), |_| 0.0);
        let w = sim.world();
        let v = w.particles.velocity[0];
        let error = if parted.ended {
            (v.norm() / speed - 1.0)
                .abs()
                .max(v.xy().norm() / speed)
                .max(w.angular_velocity(0).norm() * r / speed)
        } else {
            Real::INFINITY
        };
        worst = worst.max(error);
    }
    worst
}
