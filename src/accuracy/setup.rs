//! What the reference problems share: a world of a scene's kinds and materials over
//! a plane, materials made frictionless or elastic, a run until a contact ends.

use std::ops::ControlFlow;

use nalgebra::{Point3, UnitQuaternion, Vector3};

use crate::Real;
use crate::contact::Material;
use crate::geometry::{Shape, surfaces};
use crate::scene::{Scene, Simulation};
use crate::world::{BodyType, Wall, World};

/// A square plane through the origin, normal +z, `40 r` across, of `material`.
pub fn plane(material: usize, r: Real) -> Wall {
    let s = surfaces::plane(Point3::origin(), Vector3::z(), 40.0 * r)
        .expect("a plane of positive size");
    Wall::new("plane", material, s.vertices, s.triangles, 2.0 * r)
}

/// An empty world with the scene's materials, changed by `material` (friction,
/// restitution of a reference problem), `types` and `walls`, without gravity.
pub fn world(
    scene: &Scene,
    material: impl Fn(&mut Material),
    types: Vec<BodyType>,
    walls: Vec<Wall>,
) -> World {
    let mut materials = scene.world.materials.clone();
    materials.iter_mut().for_each(material);
    World {
        materials,
        body_types: types,
        walls,
        gravity: Vector3::zeros(),
        ..World::default()
    }
}

/// One particle of type `t` turned by `q`, its lowest point `gap` above a plane
/// of `material` (sized by the particle's circumradius), moving at `velocity`, in
/// a [`world`] whose materials `change` alters.
pub fn dropped_on_plane(
    scene: &Scene,
    change: impl Fn(&mut Material),
    t: &BodyType,
    q: UnitQuaternion<Real>,
    material: usize,
    gap: Real,
    velocity: Vector3<Real>,
) -> World {
    let radius = t.shape.circumradius();
    let mut world = self::world(
        scene,
        change,
        vec![t.clone()],
        vec![plane(material, radius)],
    );
    let lowest = depth_below(&t.shape, &q);
    world
        .particles
        .push(0, Point3::new(0.0, 0.0, lowest + gap), q, 0);
    world.particles.velocity[0] = velocity;
    world
}

/// The material of the plane a kind meets: the scene's first wall's, or the
/// kind's own in a scene without walls.
pub fn plane_material(scene: &Scene, kind: usize) -> usize {
    let w = &scene.world;
    w.walls
        .first()
        .map_or(w.body_types[kind].material, |wall| wall.material)
}

/// The turn that points body direction `down` straight down (−z); a half turn
/// about x for a direction already pointing up.
pub fn turned_down(down: &Vector3<Real>) -> UnitQuaternion<Real> {
    UnitQuaternion::rotation_between(down, &-Vector3::z()).unwrap_or_else(|| {
        UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI)
    })
}

/// Frictionless (sliding and rolling) materials.
pub fn frictionless(m: &mut Material) {
    m.friction = 0.0;
    m.rolling_friction = 0.0;
    m.rolling_damping = 0.0;
}

/// Frictionless and perfectly elastic materials.
pub fn elastic(m: &mut Material) {
    frictionless(m);
    m.restitution = 1.0;
}

/// The height of the lowest point of `shape` turned by `q` below its centroid.
pub fn depth_below(shape: &Shape, q: &UnitQuaternion<Real>) -> Real {
    match shape {
        Shape::Sphere(s) => s.radius,
        Shape::Polyhedron(p) => p
            .vertices()
            .iter()
            .map(|v| -(q * v).z)
            .fold(Real::NEG_INFINITY, Real::max),
    }
}

/// Steps `sim` until the contact it starts free of has begun and ended (or until
/// `end`); returns the steps in contact and the deepest `depth` seen during it.
pub fn until_parted(sim: &mut Simulation, end: Real, depth: impl Fn(&World) -> Real) -> Parted {
    let mut parted = Parted::default();
    let mut touched = false;
    let _ = sim.advance_to(end, |sim, _| {
        let touching = sim.stats().contacts > 0;
        touched |= touching;
        if touching {
            parted.contact_steps += 1;
            parted.deepest = parted.deepest.max(depth(sim.world()));
        }
        if touched && !touching {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    });
    parted.ended = touched && sim.stats().contacts == 0;
    parted
}

/// What [`until_parted`] saw.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Parted {
    /// Steps with a contact.
    pub contact_steps: u64,
    /// The deepest penetration during the contact.
    pub deepest: Real,
    /// Whether the contact began and ended before the time ran out.
    pub ended: bool,
}

/// When to give up on a contact of a body of radius `r` that closes at `speed`:
/// far more than any contact lasts at a resolved step, a bound for one that never
/// ends.
pub fn contact_deadline(scene: &Scene, r: Real, speed: Real) -> Real {
    200.0 * r / speed + 1e5 * scene.dt
}
