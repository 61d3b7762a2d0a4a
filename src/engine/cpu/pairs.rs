//! The particle-pair stages: every candidate pair's contact, in parallel over the flat
//! pair array, then every particle gathering its pairs' forces in pair order.

use nalgebra::Vector3;
use rayon::prelude::*;

use super::contact_state::ContactState;
use super::dispatch::pair_geometry;
use super::forces::{ContactForce, pair_force};
use crate::Real;
use crate::engine::laws::ContactLaws;
use crate::engine::neighbours::NeighbourList;
use crate::world::World;

/// Smallest share of pairs and of particles one rayon task takes.
const PAIRS_PER_TASK: usize = 64;
const PARTICLES_PER_TASK: usize = 256;

/// Evaluates every candidate pair into `results` (aligned with the pairs). Each
/// pair's history is replaced by the one its contact leaves (empty when they do not
/// touch). Two passive particles (frozen or ghost) push on nothing that moves here:
/// their pair is skipped.
pub(super) fn pair_contacts(
    world: &World,
    list: &NeighbourList,
    state: &mut ContactState,
    radii: &[Real],
    laws: &ContactLaws,
    dt: Real,
    results: &mut Vec<Option<ContactForce>>,
) {
    let p = &world.particles;
    results.clear();
    results.par_extend(
        list.pairs()
            .par_iter()
            .zip(&mut state.pair_history)
            .zip(&mut state.overlap_plans)
            .with_min_len(PAIRS_PER_TASK)
            .map(|((&[i, j], history), plan)| {
                let (i, j) = (i as usize, j as usize);
                let reach = radii[i] + radii[j];
                let c = if !(p.is_passive(i) && p.is_passive(j))
                    && (p.position[j] - p.position[i]).norm_squared() < reach * reach
                {
                    pair_geometry(world, i, j, plan)
                        .map(|g| pair_force(world, i, j, &g, *history, laws, dt))
                } else {
                    None
                };
                *history = c.map(|c| c.history).unwrap_or_default();
                c
            }),
    );
}

/// Sets every owned particle's force to its weight plus its pairs' forces, gathered in
/// pair order (what a serial sweep over the pairs would add), so the sums do not
/// depend on the threads; marks the particles that touch. Ghosts get no force.
/// Returns the number of contacts and their elastic energy.
pub(super) fn gather(
    world: &mut World,
    list: &NeighbourList,
    results: &[Option<ContactForce>],
    touching: &mut Vec<bool>,
) -> (usize, Real) {
    let p = &mut world.particles;
    let owned = p.owned();
    let (types, gravity, position) = (&world.body_types, world.gravity, &p.position);
    touching.resize(p.len(), false);
    (&mut p.force, &mut p.torque, touching)
        .into_par_iter()
        .enumerate()
        .with_min_len(PARTICLES_PER_TASK)
        .for_each(|(k, (force, torque, touching))| {
            *torque = Vector3::zeros();
            if k >= owned {
                *force = Vector3::zeros();
                *touching = false;
                return;
            }
            *force = gravity * types[p.body_type[k] as usize].mass;
            // A frozen particle is part of a bed, whether or not its contacts are
            // evaluated.
            *touching = p.frozen[k];
            for &index in list.incident(k) {
                let Some(c) = &results[index as usize] else {
                    continue;
                };
                *touching = true;
                let [i, j] = list.pairs()[index as usize].map(|x| x as usize);
                if j == k {
                    *force += c.force;
                    *torque += c.torque;
                } else {
                    *force -= c.force;
                    *torque += c.reaction_torque(&position[i], &position[j]);
                }
            }
        });
    let (mut contacts, mut energy) = (0, 0.0);
    for c in results.iter().flatten() {
        contacts += 1;
        energy += c.energy;
    }
    (contacts, energy)
}
