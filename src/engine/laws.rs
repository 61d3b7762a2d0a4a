//! Contact-law parameters the engine prepares before the contacts are evaluated.
//!
//! Every contact between two body types shares its stiffness, damping table,
//! friction, regularisation volume and effective moment of inertia. They are
//! gathered once per step into a table indexed by the two types, so that a contact
//! reads them with one index instead of recomputing cube roots and hashing its
//! restitution (measured: a tenth of the cost of a dense dodecahedron bed's step).
//! The table is rebuilt every step (a handful of types makes it cheap), so that
//! materials changed between steps take effect; the damping tables, whose
//! calibration is the costly part, are kept for every restitution seen.

use std::borrow::Cow;

use super::fast_hash::FastMap;
use crate::Real;
use crate::contact::{DampingTable, PairStiffness};
use crate::world::World;

/// Restitution of a pair of materials: the mean of the two.
pub(super) fn pair_restitution(a: Real, b: Real) -> Real {
    0.5 * (a + b)
}

/// What every contact of one pair of body types shares.
#[derive(Clone, Copy, Debug)]
pub(super) struct PairLaw {
    pub stiffness: PairStiffness,
    /// Index of the pair's damping table in [`ContactLaws`].
    table: usize,
    /// Coulomb friction coefficient (the mean of the materials').
    pub friction: Real,
    /// Regularisation volume `V₀` of the normal law.
    pub regularisation: Real,
    /// Effective moment of inertia `1/(1/I₁ + 1/I₂)` (smallest principal moments).
    pub inertia: Real,
}

/// Damping tables per restitution and the [`PairLaw`] of every pair of body types.
#[derive(Clone, Debug, Default)]
pub(super) struct ContactLaws {
    /// Calibrated damping, one table per restitution value.
    tables: Vec<DampingTable>,
    /// Index into `tables` by the restitution's bit pattern (looked up per wall
    /// contact every step).
    table_of: FastMap<u64, usize>,
    /// Row-major over (type of body 1, type of body 2).
    pairs: Vec<PairLaw>,
    types: usize,
}

impl ContactLaws {
    /// Prepares the tables for `world`'s materials and body types; `regularisation_length`
    /// is relative to the smaller equivalent radius of a pair (see
    /// [`crate::contact::normal_force`]).
    pub(super) fn prepare(&mut self, world: &World, regularisation_length: Real) {
        for a in &world.materials {
            for b in &world.materials {
                self.table_index(pair_restitution(a.restitution, b.restitution));
            }
        }
        let types = &world.body_types;
        self.types = types.len();
        self.pairs.clear();
        for ti in types {
            for tj in types {
                let (mi, mj) = (&world.materials[ti.material], &world.materials[tj.material]);
                let (ri, rj) = (ti.shape.equivalent_radius(), tj.shape.equivalent_radius());
                let e = pair_restitution(mi.restitution, mj.restitution);
                self.pairs.push(PairLaw {
                    stiffness: PairStiffness::particles(mi, ri, mj, rj),
                    table: self.table_of[&e.to_bits()],
                    friction: 0.5 * (mi.friction + mj.friction),
                    regularisation: (regularisation_length * ri.min(rj)).powi(3),
                    inertia: 1.0 / (1.0 / ti.inertia.min() + 1.0 / tj.inertia.min()),
                });
            }
        }
    }

    fn table_index(&mut self, e: Real) -> usize {
        *self.table_of.entry(e.to_bits()).or_insert_with(|| {
            self.tables.push(DampingTable::new(e));
            self.tables.len() - 1
        })
    }

    /// The law of a contact between body types `a` and `b`.
    #[inline]
    pub(super) fn pair(&self, a: u32, b: u32) -> &PairLaw {
        &self.pairs[a as usize * self.types + b as usize]
    }

    /// The damping table of `law`.
    #[inline]
    pub(super) fn damping(&self, law: &PairLaw) -> &DampingTable {
        &self.tables[law.table]
    }

    /// The calibrated damping of restitution `e`: borrowed when prepared, calibrated
    /// afresh otherwise.
    pub(super) fn damping_of(&self, e: Real) -> Cow<'_, DampingTable> {
        match self.table_of.get(&e.to_bits()) {
            Some(&k) => Cow::Borrowed(&self.tables[k]),
            None => Cow::Owned(DampingTable::new(e)),
        }
    }
}
