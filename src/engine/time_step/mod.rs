//! The suggested time step: a fraction of the shortest contact period the scene can
//! produce.
//!
//! For every pair of body types, and every body type against every wall material,
//! the stiffest normal contact the law allows is bounded and turned into a period
//! `T = 2π √(m_eff / k)`:
//!
//! - polyhedra: the flat (face on face) contact in its regularised range has the
//!   largest stiffness, `k = κ A² / V₀^{2/3}` (see [`crate::contact::normal_force`]),
//!   with `A` the smaller of the two bodies' contact areas: the largest face, or
//!   for a finely faceted body (an icosphere of 20 480 facets) the area that gives
//!   the flat contact the stiffness of its circumscribed sphere (below), whichever
//!   is larger: without it the step grew as the facets shrank, fourfold per
//!   icosphere level, and a fine icosphere's impact went unstable;
//! - spheres (against anything): the tangent stiffness of a sphere pressed on a plane
//!   (volume law) or on its partner (Hertz–Mindlin, `2 E* √(R* δ)`) to a depth of
//!   [`SPHERE_REFERENCE_DEPTH`] of its radius (the laws' stiffness grows with depth,
//!   and a contact deeper than that means the material is too soft for the scene);
//! - `m_eff` is the smallest effective mass the pair can present at a contact point:
//!   for each body `1/m + r_c² / I_min` (`r_c` the circumradius), combined in series.
//!
//! # Many body types
//!
//! The shortest period over every pair of body types is found without visiting every
//! pair (`search.rs`): every stiffness above grows with a partner's `E/R`, face area
//! and sphere radius and falls with its radius, and the effective mass grows with the
//! partner's mass, so the envelope of a group of types bounds the period of any
//! contact with a member, and groups whose bound cannot beat the shortest period
//! found are never opened.
//!
//! The suggested step is `T / STEPS_PER_PERIOD`. The velocity-Verlet limit for a
//! linear spring is `T / π`; at 30 steps per period the realised restitution of flat
//! and edge impacts is within 1 % of the requested one (at 20, e = 0.1 flat is 2.5 % off),
//! and within 2 % at three
//! times the suggested step (`tests/validation_restitution.rs`), for contacts that
//! begin at the start of a step. Where in a step a short contact begins matters: over
//! that phase, a face of the settling box's soft dodecahedra (e = 0.1) meeting the
//! steel floor realises a restitution up to 11 % off at the suggested step, falling
//! in proportion to the step (`talus accuracy` measures it for a scene). The bound on
//! stiffness and mass is conservative, so the suggestion has margin against
//! instability, not against that error.

mod search;

use self::search::shortest_pair_period;
use crate::Real;
use crate::contact::{HertzMindlinPair, Material, effective_radius};
use crate::engine::RoundLaw;
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

/// The area of the stiffest contact of polyhedron `p` (regularisation volume `v0`,
/// `g = v0^{2/3}`): its largest face, or, for a finely faceted body (an icosphere, a
/// scanned pebble), the curved contact of its circumscribed sphere, whose area at
/// the reference depth is larger than any one face's. The area is the one that
/// gives a flat contact the sphere's stiffness: `κ A² / g = k_sphere`.
fn contact_area(p: &ConvexPolyhedron, v0: Real, g: Real) -> Real {
    let curved = (sphere_stiffness(p.circumradius(), 1.0, v0) * g).sqrt();
    largest_face_area(p).max(curved)
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

/// What the step needs of a body type, or the envelope of a group of them.
#[derive(Clone, Copy, Debug)]
struct Features {
    /// `E/R` (R the volume-equivalent radius): the type's share of `κ`.
    stiffness: Real,
    /// Volume-equivalent radius (of the regularisation volume).
    radius: Real,
    /// Sphere radius, or infinite for a polyhedron.
    sphere: Real,
    /// Largest face area (polyhedra).
    face: Real,
    /// `V₀^{2/3}` of the type's own regularisation volume `(l R)³`.
    regularisation: Real,
    /// `face² / regularisation`: the size-free part of a flat contact's stiffness, by
    /// which any partner's is bounded (see [`Laws::bound`]).
    flatness: Real,
    /// Smallest effective mass at a contact point.
    mass: Real,
    material: usize,
}

impl Features {
    fn of(t: &BodyType, materials: &[Material], regularisation_length: Real) -> Self {
        let radius = t.shape.equivalent_radius();
        let v0 = (regularisation_length * radius).powi(3);
        let regularisation = v0.powf(2.0 / 3.0);
        let face = t
            .shape
            .as_polyhedron()
            .map_or(0.0, |p| contact_area(p, v0, regularisation));
        Features {
            stiffness: materials[t.material].young / radius,
            radius,
            sphere: t.shape.as_sphere().map_or(Real::INFINITY, |s| s.radius),
            face,
            regularisation,
            flatness: face * face / regularisation,
            mass: smallest_effective_mass(t),
            material: t.material,
        }
    }

    fn is_sphere(&self) -> bool {
        self.sphere.is_finite()
    }

    /// The envelope of `self` and `other` (of one material and kind): every stiffness
    /// of a contact with it is at least that with either.
    fn envelope(self, other: &Features) -> Self {
        Features {
            stiffness: self.stiffness.max(other.stiffness),
            radius: self.radius.min(other.radius),
            sphere: self.sphere.max(other.sphere),
            face: self.face.max(other.face),
            regularisation: self.regularisation.min(other.regularisation),
            flatness: self.flatness.max(other.flatness),
            mass: self.mass.min(other.mass),
            material: self.material,
        }
    }
}

/// How the contacts are stiff: the materials, the regularisation and the law.
struct Laws<'a> {
    materials: &'a [Material],
    regularisation_length: Real,
    round: RoundLaw,
}

impl Laws<'_> {
    /// Stiffest normal contact between types of features `a` and `b`.
    fn stiffness(&self, a: &Features, b: &Features) -> Real {
        let kappa = a.stiffness + b.stiffness;
        if !a.is_sphere() && !b.is_sphere() {
            // `(l min R)³` to the power 2/3 is the smaller of the two types' own
            // (monotone functions pick the same operand), without a power per pair.
            let area = a.face.min(b.face);
            return kappa * area * area / a.regularisation.min(b.regularisation);
        }
        let v0 = (self.regularisation_length * a.radius.min(b.radius)).powi(3);
        // A sphere is involved: the smaller sphere pressed on its partner.
        let r = a.sphere.min(b.sphere);
        match self.round {
            RoundLaw::Volume => sphere_stiffness(r, kappa, v0),
            RoundLaw::HertzMindlin { .. } => {
                let (ma, mb) = (&self.materials[a.material], &self.materials[b.material]);
                let young = HertzMindlinPair::new(ma, mb, 1.0).young;
                hertz_stiffness(young, a.sphere, b.sphere, r)
            }
        }
    }

    /// Period of the stiffest contact between types of features `a` and `b`, if
    /// they have one.
    fn period(&self, a: &Features, b: &Features) -> Option<Real> {
        period(self.stiffness(a, b), a, b)
    }

    /// A lower bound of the period of any member of the group of envelope `a` with any
    /// member of the group of envelope `group` (a type is its own envelope). Between polyhedra, `min(A₁, A₂)² / min(g₁, g₂) ≤
    /// max(A₁²/g₁, A₂²/g₂)` (g the regularisation term; the smaller g comes with its
    /// own area or a smaller one), which is tight whatever the sizes.
    fn bound(&self, a: &Features, group: &Features) -> Option<Real> {
        if a.is_sphere() || group.is_sphere() {
            return self.period(a, group);
        }
        let k = (a.stiffness + group.stiffness) * a.flatness.max(group.flatness);
        period(k, a, group)
    }
}

/// `2π √(m/k)` with `m` the two types' effective mass in series, if both are positive.
fn period(k: Real, a: &Features, b: &Features) -> Option<Real> {
    let m = 1.0 / (1.0 / a.mass + 1.0 / b.mass);
    (k > 0.0 && m > 0.0).then(|| std::f64::consts::TAU * (m / k).sqrt())
}

/// Hertz–Mindlin's tangent stiffness `2 E* √(R* δ)` at `δ = SPHERE_REFERENCE_DEPTH · r`
/// for bodies of sphere radii `ra`, `rb` (infinite: flat).
fn hertz_stiffness(young: Real, ra: Real, rb: Real, r: Real) -> Real {
    2.0 * young * (effective_radius(ra, rb) * SPHERE_REFERENCE_DEPTH * r).sqrt()
}

/// The stiffest wall contact of a body type of features `a` with walls of material
/// `wall`: as a contact with a flat, rigid partner of the wall's material.
fn wall_period(laws: &Laws, t: &BodyType, a: &Features, wall: &Material) -> Option<Real> {
    let m = a.mass;
    let pm = &laws.materials[a.material];
    let k = match (laws.round, &t.shape) {
        (RoundLaw::HertzMindlin { .. }, Shape::Sphere(s)) => {
            let young = HertzMindlinPair::new(pm, wall, 1.0).young;
            hertz_stiffness(young, s.radius, Real::INFINITY, s.radius)
        }
        _ => {
            let series = |x: Real, y: Real| x * y / (x + y);
            let kappa = 2.0 * series(pm.young, wall.young) / a.radius;
            let v0 = (laws.regularisation_length * a.radius).powi(3);
            match &t.shape {
                Shape::Polyhedron(_) => kappa * a.face * a.face / a.regularisation,
                Shape::Sphere(s) => sphere_stiffness(s.radius, kappa, v0),
            }
        }
    };
    (k > 0.0 && m > 0.0).then(|| std::f64::consts::TAU * (m / k).sqrt())
}

/// The suggested time step for `world` (its body types and walls), with a volume
/// law regularised at `regularisation_length` times the smaller equivalent radius and
/// sphere contacts under `round`. `None` when the world has no body types.
pub fn suggested_time_step(
    world: &World,
    regularisation_length: Real,
    round: RoundLaw,
) -> Option<TimeStepEstimate> {
    let laws = Laws {
        materials: &world.materials,
        regularisation_length,
        round,
    };
    let types = &world.body_types;
    let features: Vec<Features> = types
        .iter()
        .map(|t| Features::of(t, laws.materials, regularisation_length))
        .collect();
    let mut best: Option<(Real, String)> = shortest_pair_period(&features, &laws)
        .map(|(period, i, j)| (period, format!("body types {i} and {j}")));
    let mut wall_materials: Vec<usize> = world.walls.iter().map(|w| w.material).collect();
    wall_materials.sort_unstable();
    wall_materials.dedup();
    for (i, (t, f)) in types.iter().zip(&features).enumerate() {
        for &w in &wall_materials {
            let wall = &world.materials[w];
            if let Some(period) = wall_period(&laws, t, f, wall)
                && best.as_ref().is_none_or(|b| period < b.0)
            {
                let what = format!("body type {i} on walls of material '{}'", wall.name);
                best = Some((period, what));
            }
        }
    }
    best.map(|(period, limited_by)| TimeStepEstimate {
        dt: period / STEPS_PER_PERIOD,
        period,
        limited_by,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::RollingModel;
    use crate::geometry::{Sphere, generators};

    fn material(young: Real, density: Real) -> Material {
        Material::of_tests("", density, young, 0.3)
    }

    /// The bounded search finds the shortest period of the full search over every pair
    /// of body types, bit for bit, on mixtures of random shapes, spheres and
    /// materials, under both laws.
    #[test]
    fn bounded_search_equals_the_full_search() {
        let materials = vec![material(1e7, 2500.0), material(2e9, 1200.0)];
        let mut types = Vec::new();
        for k in 0..300u64 {
            // A spread of sizes, stiffnesses and masses.
            let size = 0.002 + 0.008 * ((k * 37 % 100) as Real / 100.0);
            let m = (k % 3 == 0) as usize;
            let shape = if k % 7 == 0 {
                Shape::Sphere(Sphere::new(size).unwrap())
            } else {
                Shape::Polyhedron(generators::random_convex(10, size, 0.4, k).unwrap().into())
            };
            types.push(BodyType::new(shape, &materials[m], m));
        }
        for round in [
            RoundLaw::Volume,
            RoundLaw::HertzMindlin {
                rolling: RollingModel::None,
            },
        ] {
            for regularisation_length in [1e-2, 0.2] {
                let laws = Laws {
                    materials: &materials,
                    regularisation_length,
                    round,
                };
                let features: Vec<Features> = types
                    .iter()
                    .map(|t| Features::of(t, &materials, regularisation_length))
                    .collect();
                let mut full: Option<(Real, usize, usize)> = None;
                for i in 0..features.len() {
                    for j in i..features.len() {
                        if let Some(p) = laws.period(&features[i], &features[j])
                            && full.is_none_or(|b| p < b.0)
                        {
                            full = Some((p, i, j));
                        }
                    }
                }
                assert_eq!(shortest_pair_period(&features, &laws), full);
            }
        }
    }

    /// A finely faceted sphere is as stiff as the sphere: its suggested step
    /// converges with the icosphere's level (it grew fourfold per level when only
    /// the largest face counted) and stays within a quarter of the analytic
    /// sphere's under the same law.
    #[test]
    fn a_fine_icosphere_is_stepped_like_the_sphere() {
        let materials = vec![material(1e7, 2500.0)];
        let dt = |shape: Shape| {
            let world = World {
                body_types: vec![BodyType::new(shape, &materials[0], 0)],
                materials: materials.clone(),
                ..World::default()
            };
            suggested_time_step(&world, 0.5, RoundLaw::Volume)
                .unwrap()
                .dt
        };
        let level = |l| {
            dt(Shape::Polyhedron(
                generators::icosphere(l, 0.004).unwrap().into(),
            ))
        };
        let sphere = dt(Shape::Sphere(Sphere::new(0.004).unwrap()));
        let (three, five) = (level(3), level(5));
        assert!((five / three - 1.0).abs() < 0.05, "{three:e} → {five:e}");
        assert!(
            (five / sphere - 1.0).abs() < 0.25,
            "{five:e} vs sphere {sphere:e}"
        );
    }
}
