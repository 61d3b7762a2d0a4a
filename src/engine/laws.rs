//! Contact-law parameters the engine prepares before the contacts are evaluated.
//!
//! A contact's parameters combine what each body brings (its body type's stiffness per
//! unit area `E/R` and `G/R`, regularisation volume, smallest moment of inertia) with
//! what the pair of materials brings (damping table, friction, Hertz–Mindlin moduli).
//! They are gathered into one row per body type and one per pair of materials, and a
//! contact combines two rows in a few flops ([`ContactLaws::pair`]): the preparation
//! costs O(types + materials²) per step and a contact O(1), whatever the number of
//! distinct shapes (a table per pair of body types cost O(types²), most of a step of
//! a bed of a thousand shapes). The combinations are the operations the laws define
//! (`E₁/R₁ + E₂/R₂`, `1/(1/I₁ + 1/I₂)`, the smaller `(l R)³`), so the values are bit for
//! bit those of a per-pair table. The rows are rebuilt at a step whose materials, body
//! types or regularisation differ from those they were made from, so that changes
//! between steps take effect (the check reads the body types, not their shapes); the
//! damping tables, whose calibration is the costly part, are kept for every
//! restitution seen.

use std::sync::Arc;

use nalgebra::Vector3;

use super::fast_hash::FastMap;
use crate::Real;
use crate::contact::{
    DampingTable, HertzMindlinPair, Material, PairStiffness, Regularisation, RollingParameters,
    pair_restitution,
};
use crate::engine::RoundLaw;
use crate::geometry::Shape;
use crate::world::{BodyType, World};

/// What every contact of one pair of body types shares.
#[derive(Clone, Copy, Debug)]
pub(super) struct PairLaw {
    pub stiffness: PairStiffness,
    /// Index of the pair's damping table in [`ContactLaws`].
    table: usize,
    /// Coulomb friction coefficient (the mean of the materials').
    pub friction: Real,
    /// Regularisation volume `V₀` of the normal law.
    pub regularisation: Regularisation,
    /// Effective moment of inertia `1/(1/I₁ + 1/I₂)` (smallest principal moments).
    pub inertia: Real,
}

/// One body type's row as a device's volume law reads it (see
/// [`ContactLaws::type_rows`]).
#[cfg(feature = "cuda")]
#[derive(Clone, Copy, Debug)]
pub(super) struct VolumeTypeRow {
    /// `E/R` and `G/R`.
    pub stiffness: PairStiffness,
    pub regularisation: Regularisation,
    /// The smallest principal moment, and its inverse.
    pub inertia: Real,
    pub inverse_inertia: Real,
    /// The volume-equivalent radius.
    pub radius: Real,
    pub material: usize,
}

/// One body type's share of its contacts' parameters.
#[derive(Clone, Copy, Debug)]
struct TypeRow {
    /// `E/R` and `G/R` (R the volume-equivalent radius).
    stiffness: PairStiffness,
    /// `(l R)³`: the regularisation volume of a contact in which this type is the
    /// smaller body.
    regularisation: Regularisation,
    /// Smallest principal moment of inertia `I_min`, and its inverse.
    inertia: Real,
    inverse_inertia: Real,
    /// Volume-equivalent radius.
    radius: Real,
    material: usize,
    /// What a sphere's own path reads, for a sphere type.
    sphere: Option<SphereBody>,
}

/// A sphere body type as its own contact path reads it.
#[derive(Clone, Copy, Debug)]
pub(super) struct SphereBody {
    pub radius: Real,
    pub inverse_mass: Real,
    /// `1 / I` (isotropic).
    pub inverse_inertia: Real,
    /// `I + m r²`: the rolling inertia about a contact point.
    pub rolling_inertia: Real,
    pub material: usize,
}

/// One pair of materials' share of its contacts' parameters (walls included).
#[derive(Clone, Copy, Debug)]
pub(super) struct MaterialPair {
    /// Index of the pair's damping table (`usize::MAX` where no contact follows the
    /// volume law, see [`ContactLaws::prepare`]).
    table: usize,
    /// Coulomb friction coefficient (the mean of the materials').
    pub friction: Real,
    /// `2 E₁E₂/(E₁ + E₂)` and the same of the shear moduli: a particle's moduli in
    /// series with a wall's, times the two of a flat wall (see
    /// [`PairStiffness::particle_wall`]).
    wall_series: PairStiffness,
    /// Moduli and damping of the Hertz–Mindlin law.
    pub hertz: HertzMindlinPair,
    /// Rolling resistance (means of the materials').
    pub rolling: RollingParameters,
}

/// Damping tables per restitution, and the rows a contact's parameters are combined
/// from.
#[derive(Clone, Debug, Default)]
pub(super) struct ContactLaws {
    /// Calibrated damping, one table per restitution value.
    tables: Vec<DampingTable>,
    /// Index into `tables` by the restitution's bit pattern.
    table_of: FastMap<u64, usize>,
    /// One row per body type.
    types: Vec<TypeRow>,
    /// Row-major over (material 1, material 2).
    materials: Vec<MaterialPair>,
    material_count: usize,
    /// What the rows were made from.
    made_from: Inputs,
}

/// What [`ContactLaws::prepare`] made the rows from, as it can be read without
/// following a body type's shape pointer: a step whose world has not changed them
/// rebuilds nothing (in a scene of 10 000 shapes, reading each body type's shape for
/// its radius is a cache miss each: the rows took 4.5 % of a step, their check takes
/// 0.7 %).
#[derive(Clone, Debug, Default, PartialEq)]
struct Inputs {
    materials: Vec<Material>,
    types: Vec<TypeInputs>,
    regularisation_length: Real,
    volume_law: bool,
}

/// A body type's share of [`Inputs`]: its shape by address (a polyhedron is shared,
/// and never changed behind its `Arc`) or by radius.
#[derive(Clone, Copy, Debug, PartialEq)]
struct TypeInputs {
    polyhedron: usize,
    sphere_radius: Real,
    material: usize,
    mass: Real,
    inertia: Vector3<Real>,
}

impl TypeInputs {
    fn of(t: &BodyType) -> Self {
        let (polyhedron, sphere_radius) = match &t.shape {
            Shape::Polyhedron(p) => (Arc::as_ptr(p).addr(), 0.0),
            Shape::Sphere(s) => (0, s.radius),
        };
        TypeInputs {
            polyhedron,
            sphere_radius,
            material: t.material,
            mass: t.mass,
            inertia: t.inertia,
        }
    }
}

impl Inputs {
    /// Whether these are the inputs of `world` with the other arguments of
    /// [`ContactLaws::prepare`].
    fn are(&self, world: &World, regularisation_length: Real, volume_law: bool) -> bool {
        self.regularisation_length == regularisation_length
            && self.volume_law == volume_law
            && self.materials == world.materials
            && self.types.len() == world.body_types.len()
            && self
                .types
                .iter()
                .zip(&world.body_types)
                .all(|(kept, t)| *kept == TypeInputs::of(t))
    }
}

impl ContactLaws {
    /// Prepares the rows for `world`'s materials and body types; `regularisation_length`
    /// is relative to the smaller equivalent radius of a pair (see
    /// [`crate::contact::normal_force`]).
    ///
    /// The volume law's damping tables are calibrated only when a contact can follow
    /// that law: not in a scene of spheres under Hertz–Mindlin (a calibration costs a
    /// few tenths of a second). Returns whether the rows were made anew (as they are
    /// whenever a body type's shape, by address, or a sphere's radius changes).
    pub(super) fn prepare(
        &mut self,
        world: &World,
        regularisation_length: Real,
        round: RoundLaw,
    ) -> bool {
        let materials = &world.materials;
        let volume_law = round == RoundLaw::Volume
            || world
                .body_types
                .iter()
                .any(|t| t.shape.as_sphere().is_none());
        if self.made_from.are(world, regularisation_length, volume_law) {
            return false;
        }
        self.made_from = Inputs {
            materials: materials.clone(),
            types: world.body_types.iter().map(TypeInputs::of).collect(),
            regularisation_length,
            volume_law,
        };
        self.material_count = materials.len();
        self.materials.clear();
        for a in materials {
            for b in materials {
                let e = pair_restitution(a.restitution, b.restitution);
                let table = if volume_law {
                    self.table_index(e)
                } else {
                    usize::MAX
                };
                let series = |x: Real, y: Real| x * y / (x + y);
                self.materials.push(MaterialPair {
                    table,
                    friction: 0.5 * (a.friction + b.friction),
                    wall_series: PairStiffness {
                        normal: 2.0 * series(a.young, b.young),
                        tangential: 2.0 * series(a.shear_modulus(), b.shear_modulus()),
                    },
                    hertz: HertzMindlinPair::new(a, b, e),
                    rolling: RollingParameters::mean(a, b),
                });
            }
        }
        self.types.clear();
        self.types.extend(world.body_types.iter().map(|t| {
            let m = &materials[t.material];
            let radius = t.shape.equivalent_radius();
            TypeRow {
                stiffness: PairStiffness {
                    normal: m.young / radius,
                    tangential: m.shear_modulus() / radius,
                },
                regularisation: Regularisation::of_length(regularisation_length * radius),
                inertia: t.inertia.min(),
                inverse_inertia: 1.0 / t.inertia.min(),
                radius,
                material: t.material,
                sphere: t.shape.as_sphere().map(|s| SphereBody {
                    radius: s.radius,
                    inverse_mass: 1.0 / t.mass,
                    inverse_inertia: 1.0 / t.inertia.x,
                    rolling_inertia: t.inertia.x + t.mass * s.radius * s.radius,
                    material: t.material,
                }),
            }
        }));
        true
    }

    fn table_index(&mut self, e: Real) -> usize {
        *self.table_of.entry(e.to_bits()).or_insert_with(|| {
            self.tables.push(DampingTable::new(e));
            self.tables.len() - 1
        })
    }

    /// The materials' share of a contact between materials `a` and `b`.
    #[inline]
    pub(super) fn materials(&self, a: usize, b: usize) -> &MaterialPair {
        &self.materials[a * self.material_count + b]
    }

    /// Body type `t` as a sphere's own path reads it, if it is a sphere.
    #[inline]
    pub(super) fn sphere(&self, t: u32) -> Option<&SphereBody> {
        self.types[t as usize].sphere.as_ref()
    }

    /// The law of a contact between body types `a` and `b`.
    #[inline]
    pub(super) fn pair(&self, a: u32, b: u32) -> PairLaw {
        let (ta, tb) = (&self.types[a as usize], &self.types[b as usize]);
        let m = self.materials(ta.material, tb.material);
        PairLaw {
            stiffness: PairStiffness {
                normal: ta.stiffness.normal + tb.stiffness.normal,
                tangential: ta.stiffness.tangential + tb.stiffness.tangential,
            },
            table: m.table,
            friction: m.friction,
            regularisation: ta.regularisation.min(tb.regularisation),
            inertia: 1.0 / (ta.inverse_inertia + tb.inverse_inertia),
        }
    }

    /// The law of a contact between body type `t` and a wall of material `wall`.
    #[inline]
    pub(super) fn wall(&self, t: u32, wall: usize) -> PairLaw {
        let row = &self.types[t as usize];
        let m = self.materials(row.material, wall);
        PairLaw {
            stiffness: PairStiffness {
                normal: m.wall_series.normal / row.radius,
                tangential: m.wall_series.tangential / row.radius,
            },
            table: m.table,
            friction: m.friction,
            regularisation: row.regularisation,
            inertia: row.inertia,
        }
    }

    /// Per body type, what the device's volume law combines a contact from
    /// (`kernels/volume_law.cuh`).
    #[cfg(feature = "cuda")]
    pub(super) fn type_rows(&self) -> impl Iterator<Item = VolumeTypeRow> + '_ {
        self.types.iter().map(|t| VolumeTypeRow {
            stiffness: t.stiffness,
            regularisation: t.regularisation,
            inverse_inertia: t.inverse_inertia,
            inertia: t.inertia,
            radius: t.radius,
            material: t.material,
        })
    }

    /// Per pair of materials, row-major: the friction coefficient, the damping
    /// table of the volume law (`None` where no contact follows it) and the moduli
    /// in series of a particle against a wall.
    #[cfg(feature = "cuda")]
    pub(super) fn material_rows(
        &self,
    ) -> impl Iterator<Item = (Real, Option<&DampingTable>, PairStiffness)> {
        self.materials
            .iter()
            .map(|m| (m.friction, self.tables.get(m.table), m.wall_series))
    }

    /// The number of materials the rows are made for.
    #[cfg(feature = "cuda")]
    pub(super) fn material_count(&self) -> usize {
        self.material_count
    }

    /// The damping table of `law`.
    #[inline]
    pub(super) fn damping(&self, law: &PairLaw) -> &DampingTable {
        &self.tables[law.table]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::Material;
    use crate::geometry::{Shape, Sphere, generators};
    use crate::world::BodyType;

    fn material(young: Real, restitution: Real, friction: Real) -> Material {
        Material {
            name: format!("m{young}"),
            density: 2000.0,
            young,
            poisson: 0.25,
            restitution,
            friction,
            rolling_friction: 0.0,
            rolling_damping: 0.0,
        }
    }

    /// The combined rows give the per-pair values of the laws' definitions, bit for
    /// bit (what a table per pair of body types held).
    #[test]
    fn combined_rows_equal_the_pair_definitions() {
        let mut world = World {
            materials: vec![material(1e7, 0.5, 0.3), material(3e8, 0.9, 0.6)],
            ..Default::default()
        };
        let shapes = [
            Shape::Sphere(Sphere::new(0.004).unwrap()),
            Shape::Polyhedron(generators::cuboid(0.01, 0.02, 0.005).unwrap().into()),
            Shape::Polyhedron(generators::random_convex(12, 0.007, 0.3, 5).unwrap().into()),
        ];
        for (k, s) in shapes.iter().enumerate() {
            let m = k % 2;
            world
                .body_types
                .push(BodyType::new(s.clone(), &world.materials[m], m));
        }
        let mut laws = ContactLaws::default();
        let l = 0.05;
        laws.prepare(&world, l, RoundLaw::Volume);
        for (i, a) in world.body_types.iter().enumerate() {
            for (j, b) in world.body_types.iter().enumerate() {
                let (ma, mb) = (&world.materials[a.material], &world.materials[b.material]);
                let (ra, rb) = (a.shape.equivalent_radius(), b.shape.equivalent_radius());
                let law = laws.pair(i as u32, j as u32);
                assert_eq!(law.stiffness, PairStiffness::particles(ma, ra, mb, rb));
                assert_eq!(law.friction, 0.5 * (ma.friction + mb.friction));
                assert_eq!(law.regularisation.volume(), (l * ra.min(rb)).powi(3));
                assert_eq!(
                    law.inertia,
                    1.0 / (1.0 / a.inertia.min() + 1.0 / b.inertia.min())
                );
                let e = 0.5 * (ma.restitution + mb.restitution);
                assert_eq!(laws.damping(&law).restitution(), e);
            }
            for (w, wm) in world.materials.iter().enumerate() {
                let law = laws.wall(i as u32, w);
                let pm = &world.materials[a.material];
                let r = a.shape.equivalent_radius();
                assert_eq!(law.stiffness, PairStiffness::particle_wall(pm, r, wm));
                assert_eq!(law.regularisation.volume(), (l * r).powi(3));
                assert_eq!(law.friction, 0.5 * (pm.friction + wm.friction));
            }
        }
    }

    /// Rows made once are kept while nothing they depend on changes, and made again
    /// when a material changes, a body type is added or changed, or the
    /// regularisation changes between steps.
    #[test]
    fn rows_follow_changes_between_steps() {
        let mut world = World {
            materials: vec![material(1e7, 0.5, 0.3)],
            ..Default::default()
        };
        let cube = Shape::Polyhedron(generators::cuboid(0.01, 0.01, 0.01).unwrap().into());
        let body = BodyType::new(cube, &world.materials[0], 0);
        world.body_types.push(body);
        let mut laws = ContactLaws::default();
        // The rows of type 0, where they were made anew (the type table of the CPU
        // backend is made anew with them).
        let prepare = |laws: &mut ContactLaws, world: &World, l: Real| {
            let made = laws.prepare(world, l, RoundLaw::Volume);
            assert!(made, "the rows were not made anew");
            laws.pair(0, 0)
        };
        let first = prepare(&mut laws, &world, 0.05);
        assert_eq!(first.friction, 0.3);
        // The same world: the same rows.
        assert!(!laws.prepare(&world, 0.05, RoundLaw::Volume));
        let again = laws.pair(0, 0);
        assert_eq!(again.stiffness, first.stiffness);
        assert_eq!(again.friction, first.friction);
        // A material changed in place.
        world.materials[0].friction = 0.7;
        world.materials[0].young = 2e7;
        let changed = prepare(&mut laws, &world, 0.05);
        assert_eq!(changed.friction, 0.7);
        assert_eq!(changed.stiffness.normal, 2.0 * first.stiffness.normal);
        // A body type added: a cube of twice the size.
        let large = Shape::Polyhedron(generators::cuboid(0.02, 0.02, 0.02).unwrap().into());
        let large = BodyType::new(large, &world.materials[0], 0);
        world.body_types.push(large.clone());
        let larger = prepare(&mut laws, &world, 0.05);
        assert_eq!(larger.stiffness, changed.stiffness);
        let ratio = changed.stiffness.normal / laws.pair(1, 1).stiffness.normal;
        assert!((ratio - 2.0).abs() < 1e-12, "{ratio}");
        // A body type changed in place: the large cube in the first one's place.
        world.body_types[0] = large;
        let larger = prepare(&mut laws, &world, 0.05);
        let ratio = changed.stiffness.normal / larger.stiffness.normal;
        assert!((ratio - 2.0).abs() < 1e-12, "{ratio}");
        // Another regularisation length.
        let regularised = prepare(&mut laws, &world, 0.1);
        let ratio = regularised.regularisation.volume() / larger.regularisation.volume();
        assert!((ratio - 8.0).abs() < 1e-12, "{ratio}");
    }
}
