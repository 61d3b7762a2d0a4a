//! The CPU backend's contact of one pair of particles, whole and alone: what the
//! other backends' kernels are checked against (`engine/cuda`'s tests).

use nalgebra::Vector3;

use super::dispatch::pair_geometry;
use super::forces::{PairResult, pair_force};
use crate::Real;
use crate::contact::TangentialHistory;
use crate::engine::laws::ContactLaws;
use crate::geometry::overlap::OverlapCache;
use crate::world::World;

/// A pair's contact as the pair stage finds it: its result and the history it
/// leaves.
#[derive(Clone, Copy, Debug)]
pub(in crate::engine) struct ReferenceContact {
    /// Force on particle `j`; `i` gets the opposite.
    pub force: Vector3<Real>,
    /// Torques on `i` and on `j` about their centroids.
    pub torques: [Vector3<Real>; 2],
    pub energy: Real,
    pub dissipated: Real,
    pub touching: bool,
    pub history: TangentialHistory,
    /// The overlap's extent along the normal (0 apart).
    pub depth: Real,
}

/// The volume-law contact of particles `i` and `j` holding `history`, over a step
/// of `dt`, evaluated afresh (no kept overlap plan).
pub(in crate::engine) fn pair_contact(
    world: &World,
    i: usize,
    j: usize,
    history: &TangentialHistory,
    laws: &ContactLaws,
    dt: Real,
) -> ReferenceContact {
    let p = &world.particles;
    let mut plan = OverlapCache::default();
    let (result, history, depth) = match pair_geometry(world, i, j, &mut plan) {
        Some(g) => {
            let c = pair_force(world, i, j, &g, *history, laws, dt);
            let result = PairResult::new(&c, &p.position[i], &p.position[j]);
            (result, c.history, g.depth)
        }
        None => (
            PairResult::parted(history),
            TangentialHistory::default(),
            0.0,
        ),
    };
    ReferenceContact {
        force: result.force,
        torques: result.torques,
        energy: result.energy,
        dissipated: result.dissipated,
        touching: result.touching,
        history,
        depth,
    }
}
