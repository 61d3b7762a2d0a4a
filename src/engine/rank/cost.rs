//! What a particle costs a rank's step, for the bisection's weights.

use crate::Real;
use crate::engine::neighbours::NeighbourList;
use crate::world::World;

/// Cost of a candidate pair with a polyhedron against one of two spheres: a
/// dodecahedron bed steps about 670 ns a contact on one thread (1.5e6 contacts/s),
/// a settled sphere bed about 170 ns (2.2 ms a step for 12 800 contacts; README,
/// "Known limits").
pub const POLYHEDRON_PAIR_COST: Real = 4.0;

/// A particle's own cost (integration, its walls) in sphere pairs: integration
/// takes 0.15 of the sphere bed's 2.2 ms for 5000 particles, walls 0.35 ms.
pub const PARTICLE_COST: Real = 0.3;

/// Each owned particle's share of a step's cost, in sphere pairs: its own cost and
/// half of each of its candidate pairs (a pair of two spheres 1, else
/// [`POLYHEDRON_PAIR_COST`]). `list` may be older than the world: particles
/// inserted since have no pairs yet (and the ghosts after them moved up by as
/// many places, which may misjudge a pair's kind, not its count).
pub fn particle_costs(world: &World, list: &NeighbourList) -> Vec<Real> {
    let p = &world.particles;
    let is_sphere = |i: usize| {
        p.body_type
            .get(i)
            .is_some_and(|&t| world.body_types[t as usize].shape.as_polyhedron().is_none())
    };
    (0..p.owned())
        .map(|i| {
            if i >= list.particle_count() {
                return PARTICLE_COST;
            }
            let pairs: Real = list
                .incident(i)
                .iter()
                .map(|e| {
                    let [a, b] = list.pairs()[e.pair()];
                    if is_sphere(a as usize) && is_sphere(b as usize) {
                        0.5
                    } else {
                        0.5 * POLYHEDRON_PAIR_COST
                    }
                })
                .sum();
            PARTICLE_COST + pairs
        })
        .collect()
}
