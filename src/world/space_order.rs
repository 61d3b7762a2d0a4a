//! An order of the particles that follows space: the Morton code (Z order) of the
//! grid cell that held a particle when the order was last refreshed, then its id.
//! The candidate lists sort their pairs by it, so each particle sums its contacts in
//! this order, and the host stores the owned particles in it.
//!
//! # Invariant
//! A particle's code ([`crate::world::Particles::cell_code`]) changes only at a
//! refresh ([`World::refresh_space_order`]), which the driver makes on a fixed
//! schedule of steps; it is saved with the state and travels with the particle to
//! other ranks. So the order of every sum depends on the state alone: not on when
//! the lists were built, their skin, the rank that holds the particle, or a restart.
//! A particle made since the last refresh has [`Particles::NO_CELL`], and so sorts
//! after every placed one, by id.
//!
//! # Why
//! Ids follow the order in which particles were made: a pour's are spread through
//! the bed it forms. Summing and storing by id made every stage read partners that
//! lie far apart in memory, and two threads read lines the other core had just
//! written for about half the contacts; in space order the pairs of neighbouring
//! particles lie together in the pair array and in memory.

use std::borrow::Cow;

use nalgebra::Point3;

use super::{BodyType, Particles, World};
use crate::Real;

/// Bits of a cell coordinate in a code: three of them fill 63 bits.
const BITS: u32 = 21;

/// The grid that codes the particles' places.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpaceOrder {
    /// Cells per unit length.
    per_length: Real,
}

impl SpaceOrder {
    /// The grid for the body types of a world: cells of twice the largest bounding
    /// radius (1 m where there are none), so that a particle's partners lie in its
    /// own cell or the next ones.
    pub fn of_types(types: &[BodyType]) -> Self {
        let largest = (types.iter())
            .map(|t| t.shape.circumradius())
            .fold(0.0, Real::max);
        let cell = if largest.is_finite() && largest > 0.0 {
            2.0 * largest
        } else {
            1.0
        };
        SpaceOrder {
            per_length: 1.0 / cell,
        }
    }

    /// The code of the cell at `x`. Cell coordinates wrap every 2²¹ cells (a
    /// particle that far away only sorts elsewhere); a position that is not finite
    /// falls into cell 0.
    #[inline]
    pub fn code(&self, x: &Point3<Real>) -> u64 {
        let cell = |v: Real| {
            let c = (v * self.per_length).floor() as i64;
            spread((c.wrapping_add(1 << (BITS - 1)) as u64) & ((1 << BITS) - 1))
        };
        cell(x.x) | cell(x.y) << 1 | cell(x.z) << 2
    }
}

/// The 21 low bits of `v` moved to every third bit.
#[inline]
fn spread(v: u64) -> u64 {
    let mut v = v & 0x1f_ffff;
    v = (v | v << 32) & 0x001f_0000_0000_ffff;
    v = (v | v << 16) & 0x001f_0000_ff00_00ff;
    v = (v | v << 8) & 0x100f_00f0_0f00_f00f;
    v = (v | v << 4) & 0x10c3_0c30_c30c_30c3;
    v = (v | v << 2) & 0x1249_2492_4924_9249;
    v
}

impl World {
    /// Codes every owned particle by the cell it lies in now and, if it `reorders`,
    /// stores the owned particles in the order of their keys `(code, id)` (the
    /// fluid's per-particle rows follow them). Returns whether any code or place
    /// changed: then whatever a backend keeps per particle must be found again by
    /// id, and the candidate lists sorted anew. Ghosts are left alone (their owners
    /// code them).
    pub fn refresh_space_order(&mut self, reorders: bool) -> bool {
        let order = SpaceOrder::of_types(&self.body_types);
        let p = &mut self.particles;
        let n = p.owned();
        let mut changed = false;
        for i in 0..n {
            let code = order.code(&p.position[i]);
            changed |= code != p.cell_code[i];
            p.cell_code[i] = code;
        }
        let keys: Vec<(u64, u64)> = (0..n).map(|i| p.space_key(i)).collect();
        if !reorders || keys.is_sorted() {
            return changed;
        }
        let mut places: Vec<u32> = (0..n as u32).collect();
        places.sort_unstable_by_key(|&k| keys[k as usize]);
        p.reorder_owned(&places);
        if let Some(fluid) = self.fluid.as_mut() {
            fluid.particles_reordered(&places, &self.particles);
        }
        true
    }
}

impl World {
    /// This world with its owned particles stored in the order of their ids and
    /// without ghosts (a copy, where they are stored otherwise): what the files of a
    /// bed's analysis read, so that they do not depend on the space order.
    pub fn in_id_order(&self) -> Cow<'_, World> {
        let p = &self.particles;
        if p.ghosts() == 0 && p.id.is_sorted() {
            return Cow::Borrowed(self);
        }
        let mut world = self.clone();
        world.particles.clear_ghosts();
        let places: Vec<u32> = (p.owned_by_id().into_iter()).map(|i| i as u32).collect();
        world.particles.reorder_owned(&places);
        if let Some(fluid) = world.fluid.as_mut() {
            fluid.particles_reordered(&places, &world.particles);
        }
        Cow::Owned(world)
    }
}

impl Particles {
    /// The owned particles' entries in the order of their ids: the order in which
    /// outputs list them, whatever the order they are stored in.
    pub fn owned_by_id(&self) -> Vec<usize> {
        self.by_id((0..self.owned()).collect())
    }

    /// `entries` (distinct entries of these particles) sorted by their particles'
    /// ids; left as they are where they already are, as after a run on one process
    /// that never stored its particles in the space order.
    pub fn by_id(&self, mut entries: Vec<usize>) -> Vec<usize> {
        if !entries.is_sorted_by_key(|&i| self.id[i]) {
            entries.sort_unstable_by_key(|&i| self.id[i]);
        }
        entries
    }

    /// The code of a particle not placed in the space order yet (made since the
    /// last refresh): it sorts after every placed particle.
    pub const NO_CELL: u64 = u64::MAX;

    /// Entry `i`'s key in the space order: its cell's code, then its id.
    #[inline]
    pub fn space_key(&self, i: usize) -> (u64, u64) {
        (self.cell_code[i], self.id[i])
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::UnitQuaternion;

    use super::*;
    use crate::contact::Material;
    use crate::geometry::{Shape, Sphere};

    /// The bits of the three coordinates interleave, x lowest.
    #[test]
    fn codes_interleave_the_cell_coordinates() {
        for v in [0u64, 1, 2, 5, 0x1f_ffff, 0x15_5555] {
            let s = spread(v);
            for b in 0..BITS {
                assert_eq!((s >> (3 * b)) & 1, (v >> b) & 1, "{v:#x} bit {b}");
            }
            assert_eq!(s & !0x1249_2492_4924_9249, 0, "{v:#x}: other bits");
        }
        let order = SpaceOrder { per_length: 1.0 };
        let origin = 1u64 << (BITS - 1);
        let code = |x: Real, y: Real, z: Real| order.code(&Point3::new(x, y, z));
        assert_eq!(code(0.5, 0.5, 0.5), spread(origin) * 0b111);
        assert_eq!(code(1.5, 0.5, 0.5), code(0.5, 0.5, 0.5) + 1);
        assert_eq!(code(0.5, 1.5, 0.5), code(0.5, 0.5, 0.5) + 2);
        assert_eq!(code(0.5, 0.5, 1.5), code(0.5, 0.5, 0.5) + 4);
        let (o, below) = (spread(origin), spread(origin - 1));
        assert_eq!(code(-0.5, 0.5, 0.5), below | o << 1 | o << 2);
        // The eight cells of a 2 × 2 × 2 block follow one another.
        let mut block: Vec<u64> = (0..8)
            .map(|k| {
                code(
                    (k & 1) as Real + 0.5,
                    (k >> 1 & 1) as Real + 0.5,
                    (k >> 2) as Real + 0.5,
                )
            })
            .collect();
        block.sort_unstable();
        assert!(block.windows(2).all(|w| w[1] == w[0] + 1), "{block:?}");
        assert_eq!(code(Real::NAN, 0.5, 0.5), code(0.0, 0.5, 0.5));
    }

    /// A refresh codes the owned particles, stores them by key with all their
    /// state, leaves the ghosts, and reports a change only where there was one.
    #[test]
    fn a_refresh_stores_the_owned_particles_by_their_keys() {
        let material = Material::of_tests("m", 1000.0, 1e7, 0.3);
        let shape = Shape::Sphere(Sphere::new(0.5).unwrap());
        let mut world = World {
            body_types: vec![BodyType::new(shape, &material, 0)],
            materials: vec![material],
            ..World::default()
        };
        // Cells of 1 m: ids 0..4 at x = 3.5, 0.5, 2.5, 0.5 (ids 1 and 3 share a cell).
        let p = &mut world.particles;
        for (id, x) in [(0, 3.5), (1, 0.5), (2, 2.5), (3, 0.7)] {
            p.push(0, Point3::new(x, 0.5, 0.5), UnitQuaternion::identity(), id);
            p.velocity[id as usize].x = id as Real;
        }
        p.push_ghost(0, Point3::new(1.5, 0.5, 0.5), UnitQuaternion::identity(), 9);
        assert!(p.cell_code.iter().all(|&c| c == Particles::NO_CELL));

        assert!(world.refresh_space_order(true));
        let p = &world.particles;
        assert_eq!(p.id, [1, 3, 2, 0, 9]);
        assert_eq!(
            p.velocity.iter().map(|v| v.x).collect::<Vec<_>>(),
            [1.0, 3.0, 2.0, 0.0, 0.0]
        );
        assert_eq!(p.index_of(0), Some(3));
        assert_eq!(p.cell_code[0], p.cell_code[1]);
        assert!(p.space_key(1) < p.space_key(2) && p.space_key(2) < p.space_key(3));
        assert_eq!(
            p.cell_code[4],
            Particles::NO_CELL,
            "a ghost keeps its owner's code"
        );

        assert!(
            !world.refresh_space_order(true),
            "nothing moved: nothing changed"
        );
        world.particles.position[0].x = 5.5;
        let codes = world.particles.cell_code.clone();
        assert!(world.refresh_space_order(false), "a code changed");
        assert_eq!(world.particles.id, [1, 3, 2, 0, 9], "in place");
        assert_ne!(world.particles.cell_code[0], codes[0]);
        assert_eq!(world.particles.cell_code[1..], codes[1..]);
        assert!(world.refresh_space_order(true));
        assert_eq!(world.particles.id, [3, 2, 0, 1, 9]);

        // Outputs read them by id.
        assert_eq!(world.particles.owned_by_id(), [2, 3, 1, 0]);
        let by_id = world.in_id_order();
        assert_eq!(by_id.particles.id, [0, 1, 2, 3]);
        let v: Vec<Real> = by_id.particles.velocity.iter().map(|v| v.x).collect();
        assert_eq!(v, [0.0, 1.0, 2.0, 3.0]);
        let by_id = by_id.into_owned();
        assert!(matches!(by_id.in_id_order(), Cow::Borrowed(_)));
    }
}
