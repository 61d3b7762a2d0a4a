//! The stages that move things: the kick–drift of the owned particles, the closing
//! kick, and the walls' prescribed motion.

use rayon::prelude::*;

use crate::Real;
use crate::engine::integrate::{RotationState, free_rotation, half_kick};
use crate::world::World;

/// Smallest share of particles one rayon task takes: below it the scheduling costs
/// more than the work.
const PARTICLES_PER_TASK: usize = 256;

/// Half kick with the forces of the last evaluation, drift, and free rotation of every
/// owned particle that is not frozen. Returns how many were integrated.
pub(crate) fn kick_drift(world: &mut World, dt: Real) -> usize {
    let types = &world.body_types;
    let p = &mut world.particles;
    let n = p.owned();
    (
        &mut p.position[..n],
        &mut p.velocity[..n],
        &mut p.orientation[..n],
        &mut p.angular_momentum[..n],
    )
        .into_par_iter()
        .zip((
            &p.force[..n],
            &p.torque[..n],
            &p.body_type[..n],
            &p.frozen[..n],
        ))
        .with_min_len(PARTICLES_PER_TASK)
        .for_each(|((x, v, q, l), (f, t, &kind, &frozen))| {
            if frozen {
                return;
            }
            let kind = &types[kind as usize];
            *v += f * (0.5 * dt / kind.mass);
            *x += *v * dt;
            let mut rot = RotationState {
                orientation: *q,
                angular_momentum: *l,
            };
            half_kick(&mut rot, t, dt);
            free_rotation(&mut rot, &kind.inertia, dt);
            *q = rot.orientation;
            *l = rot.angular_momentum;
        });
    n - p.frozen_count()
}

/// Moves every wall by its prescribed motion over `dt`, then the attached walls with
/// their leaders, and advances the clock.
pub(crate) fn advance_walls(world: &mut World, dt: Real) {
    for wall in &mut world.walls {
        wall.advance(world.time, dt);
    }
    world.follow_leaders();
    world.time += dt;
}

/// The closing half kick with the forces just evaluated.
pub(crate) fn closing_kick(world: &mut World, dt: Real) {
    let types = &world.body_types;
    let p = &mut world.particles;
    let n = p.owned();
    (&mut p.velocity[..n], &mut p.angular_momentum[..n])
        .into_par_iter()
        .zip((
            &p.force[..n],
            &p.torque[..n],
            &p.body_type[..n],
            &p.frozen[..n],
        ))
        .with_min_len(PARTICLES_PER_TASK)
        .for_each(|((v, l), (f, t, &kind, &frozen))| {
            if frozen {
                return;
            }
            *v += f * (0.5 * dt / types[kind as usize].mass);
            *l += t * (0.5 * dt);
        });
}
