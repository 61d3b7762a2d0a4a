//! Reference impacts built from a scene: each of its particle kinds dropped on a
//! plane of each of its wall materials, face, edge and vertex first (a sphere
//! once), at the scene's time step, contact laws and a speed the scene can produce.
//! What comes back is the restitution realised against the one requested and the
//! impact's own energy account: the errors to expect of the scene's contacts. Each
//! drop is made with its first contact at four places within a step ([`PHASES`]),
//! and the worst is kept.

use nalgebra::{Point3, Vector3};

use super::{KINDS_CHECKED, setup};
use crate::Real;
use crate::contact::pair_restitution;
use crate::geometry::{ConvexPolyhedron, Shape};
use crate::scene::energy_ledger::EnergyReport;
use crate::scene::{Scene, Simulation};

/// Which part of a particle meets the plane first.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Feature {
    /// The face nearest the centroid, flat on the plane (a central impact).
    Face,
    /// The edge nearest the centroid, turned halfway between its two faces.
    Edge,
    /// The vertex farthest from the centroid, straight below it (central).
    Vertex,
    /// A sphere.
    Sphere,
}

impl Feature {
    /// The feature's name in reports.
    pub fn name(self) -> &'static str {
        match self {
            Feature::Face => "face",
            Feature::Edge => "edge",
            Feature::Vertex => "vertex",
            Feature::Sphere => "sphere",
        }
    }
}

/// One reference impact and what it realised.
#[derive(Clone, Debug, PartialEq)]
pub struct Impact {
    /// The particle kind (body type) dropped.
    pub kind: usize,
    /// The plane's material (index into the scene's materials).
    pub material: usize,
    pub feature: Feature,
    /// Impact speed, m/s.
    pub speed: Real,
    /// Restitution the pair's materials ask for.
    pub requested: Real,
    /// Restitution realised: the rebound over the impact speed of the normal
    /// velocity of the material point that touched first.
    pub realised: Real,
    /// The impact's energy account error over the energy brought in (see
    /// `scene::energy_ledger`).
    pub energy_error: Real,
    /// Steps the contact lasted.
    pub contact_steps: u64,
}

impl Impact {
    /// `realised / requested − 1`.
    pub fn restitution_error(&self) -> Real {
        self.realised / self.requested - 1.0
    }
}

/// A speed the scene's contacts meet: the fastest of a fall across the scene's
/// height, the inlets' velocities and the walls' surfaces at the start (1 m/s for a
/// scene with none of them).
pub fn impact_speed(scene: &Scene) -> Real {
    let w = &scene.world;
    let g = w.gravity.norm();
    let down = w.gravity.try_normalize(0.0).unwrap_or_else(Vector3::z);
    let mut heights = w
        .walls
        .iter()
        .flat_map(|wall| wall.vertices.iter().map(|v| (wall.pose * v).coords))
        .chain(w.particles.position.iter().map(|p| p.coords))
        .chain(
            scene
                .inlets
                .iter()
                .flat_map(|i| [i.min.coords, i.max.coords]),
        )
        .map(|x| x.dot(&down));
    let first = heights.next().unwrap_or(0.0);
    let (lo, hi) = heights.fold((first, first), |(lo, hi), h| (lo.min(h), hi.max(h)));
    let fall = (2.0 * g * (hi - lo)).sqrt();
    let inlets = scene.inlets.iter().map(|i| i.velocity.norm());
    // A scene's walls carry their velocities at time 0 (`Wall::with_motion`).
    let walls = w.walls.iter().flat_map(|wall| {
        wall.vertices
            .iter()
            .map(move |v| wall.velocity_at(&(wall.pose * v)).norm())
    });
    let fastest = inlets.chain(walls).fold(fall, Real::max);
    if fastest > 0.0 { fastest } else { 1.0 }
}

/// The reference impacts of `scene` at `speed`: each of its first
/// [`KINDS_CHECKED`] particle kinds on each of its wall materials (its own material
/// without walls).
pub fn impacts(scene: &Scene, speed: Real) -> Vec<Impact> {
    let w = &scene.world;
    let mut walls: Vec<usize> = w.walls.iter().map(|wall| wall.material).collect();
    walls.sort_unstable();
    walls.dedup();
    let mut out = Vec::new();
    for (kind, t) in w.body_types.iter().enumerate().take(KINDS_CHECKED) {
        let materials = if walls.is_empty() {
            vec![t.material]
        } else {
            walls.clone()
        };
        let features: &[Feature] = match t.shape {
            Shape::Sphere(_) => &[Feature::Sphere],
            Shape::Polyhedron(_) => &[Feature::Face, Feature::Edge, Feature::Vertex],
        };
        for &material in &materials {
            for &feature in features {
                out.push(drop(scene, kind, material, feature, speed));
            }
        }
    }
    out
}

/// The direction (body frame) that is turned straight down and the point of the
/// feature met first on that line.
pub(super) fn aim(shape: &Shape, feature: Feature) -> (Vector3<Real>, Point3<Real>) {
    let p = match shape {
        Shape::Sphere(s) => return (-Vector3::z(), Point3::from(-Vector3::z() * s.radius)),
        Shape::Polyhedron(p) => p,
    };
    match feature {
        Feature::Vertex | Feature::Sphere => {
            let v = p
                .vertices()
                .iter()
                .max_by(|a, b| a.coords.norm().total_cmp(&b.coords.norm()))
                .expect("a polyhedron has vertices");
            (v.coords.normalize(), *v)
        }
        Feature::Face => {
            let plane = p
                .planes()
                .iter()
                .min_by(|a, b| a.offset.total_cmp(&b.offset))
                .expect("a polyhedron has faces");
            (plane.normal, Point3::from(plane.normal * plane.offset))
        }
        Feature::Edge => nearest_edge(p),
    }
}

/// The edge whose midpoint is nearest the centroid: the direction halfway between
/// its two faces' normals (the edge is lowest along it) and its midpoint.
fn nearest_edge(p: &ConvexPolyhedron) -> (Vector3<Real>, Point3<Real>) {
    let v = p.vertices();
    let [a, b] = *p
        .edges()
        .iter()
        .min_by(|e, f| {
            let mid = |e: &[u32; 2]| (v[e[0] as usize].coords + v[e[1] as usize].coords).norm();
            mid(e).total_cmp(&mid(f))
        })
        .expect("a polyhedron has edges");
    let normal: Vector3<Real> = (0..p.face_count())
        .filter(|&f| p.face(f).contains(&a) && p.face(f).contains(&b))
        .map(|f| p.planes()[f].normal)
        .sum();
    let mid = Point3::from((v[a as usize].coords + v[b as usize].coords) * 0.5);
    (
        normal.try_normalize(0.0).unwrap_or(mid.coords.normalize()),
        mid,
    )
}

/// Where in a step an impact's first contact falls: each drop is repeated with the
/// gap lengthened by these fractions of a step's travel, and the worst kept. A
/// short contact (a face meeting a plane lasts some 60 steps at the suggested step)
/// realises a restitution that depends on that phase by a few per cent.
pub const PHASES: [Real; 4] = [0.0, 0.25, 0.5, 0.75];

/// The drop of kind `kind` on a plane of `material`, `feature` first, at `speed`
/// that is furthest from the restitution asked for, over the [`PHASES`].
fn drop(scene: &Scene, kind: usize, material: usize, feature: Feature, speed: Real) -> Impact {
    PHASES
        .iter()
        .map(|&phase| drop_at(scene, (kind, material, feature), speed, phase))
        .max_by(|a, b| {
            let e = |i: &Impact| i.restitution_error().abs();
            e(a).total_cmp(&e(b))
        })
        .expect("phases to try")
}

/// One drop whose gap is a hundredth of the radius and `phase` of a step's travel.
fn drop_at(
    scene: &Scene,
    (kind, material, feature): (usize, usize, Feature),
    speed: Real,
    phase: Real,
) -> Impact {
    let t = &scene.world.body_types[kind];
    let (down, point) = aim(&t.shape, feature);
    let q = setup::turned_down(&down);
    let radius = t.shape.circumradius();
    let world = setup::dropped_on_plane(
        scene,
        |_| {},
        t,
        q,
        material,
        0.01 * radius + phase * speed * scene.dt,
        Vector3::new(0.0, 0.0, -speed),
    );
    let mut sim = Simulation::new(&scene.reference(world));
    let end = setup::contact_deadline(scene, radius, speed);
    let contact_steps = setup::until_parted(&mut sim, end, |_| 0.0).contact_steps;
    let w = sim.world();
    let lever = w.particles.orientation[0] * point.coords;
    let velocity = w.particles.velocity[0] + w.angular_velocity(0).cross(&lever);
    let materials = &scene.world.materials;
    Impact {
        kind,
        material,
        feature,
        speed,
        requested: pair_restitution(
            materials[t.material].restitution,
            materials[material].restitution,
        ),
        realised: velocity.z / speed,
        energy_error: EnergyReport::of(&sim).relative_error,
        contact_steps,
    }
}
