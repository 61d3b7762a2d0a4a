//! The stages that move things: the kick–drift of the owned particles, the closing
//! kick, and the walls' prescribed motion.

use rayon::prelude::*;

use crate::Real;
use crate::engine::integrate::{RotationState, free_rotation, half_kick, turned_isotropic};
use crate::geometry::is_isotropic;
use crate::world::{BodyType, World, all_finite_entries};

/// Smallest share of particles one rayon task takes: below it the scheduling costs
/// more than the work.
const PARTICLES_PER_TASK: usize = 256;

/// What a step's integration of one body type divides by, divided once: the same
/// quotients every particle of the type computed for itself before, so the same bits.
#[derive(Clone, Copy, Debug)]
struct TypeStep {
    /// `h / (2 m)`: a half kick's velocity change per newton.
    kick: Real,
    /// `h / (2 I)` of an isotropic body ([`turned_isotropic`]); `None` for another.
    turn: Option<Real>,
}

/// Every body type's [`TypeStep`], kept between steps so that a step allocates
/// nothing.
#[derive(Clone, Debug, Default)]
pub(crate) struct TypeSteps(Vec<TypeStep>);

impl TypeSteps {
    /// The steps of `types` for a step of `dt`.
    fn of(&mut self, types: &[BodyType], dt: Real) -> &[TypeStep] {
        self.0.clear();
        self.0.extend(types.iter().map(|t| TypeStep {
            kick: 0.5 * dt / t.mass,
            turn: is_isotropic(&t.inertia).then(|| 0.5 * dt / t.inertia.x),
        }));
        &self.0
    }
}

/// Half kick with the forces of the last evaluation, drift, and free rotation of every
/// owned particle that is not frozen. Returns how many were integrated.
pub(crate) fn kick_drift(world: &mut World, dt: Real, steps: &mut TypeSteps) -> usize {
    let types = &world.body_types;
    let steps = steps.of(types, dt);
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
            let step = &steps[kind as usize];
            *v += f * step.kick;
            *x += *v * dt;
            // The state in the particle's own arrays, not in a `RotationState` on the
            // stack (see `turned_isotropic`).
            match step.turn {
                Some(half_step) => {
                    half_kick(l, t, dt);
                    *q = turned_isotropic(q, l, half_step);
                }
                None => {
                    let mut rot = RotationState {
                        orientation: *q,
                        angular_momentum: *l,
                    };
                    half_kick(&mut rot.angular_momentum, t, dt);
                    free_rotation(&mut rot, &types[kind as usize].inertia, dt);
                    *q = rot.orientation;
                    *l = rot.angular_momentum;
                }
            }
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

/// The closing half kick with the forces just evaluated, and whether every owned
/// particle's position, velocity, angular momentum, force and torque are finite
/// after it (as [`crate::world::Particles::all_finite`] looks), chunk by chunk as
/// each is kicked.
///
/// Why the look here, and in the kick's chunks: by the host after the step, its
/// serial look on two threads read every line that the other core had just
/// written, and that core then fetched them back for its half of the next kick (the
/// settled bed of 5000 spheres: the integration stage 73–95 µs a step against 63–66
/// µs without the look, 2026-12-07); a pass of its own after the kick was one more
/// parallel region a step. The look reads the chunk's lines while they are in this
/// core's cache. All chunks are kicked, whatever one finds.
pub(crate) fn closing_kick(world: &mut World, dt: Real, steps: &mut TypeSteps) -> bool {
    let steps = steps.of(&world.body_types, dt);
    let p = &mut world.particles;
    let n = p.owned();
    let (position, force, torque) = (&p.position[..n], &p.force[..n], &p.torque[..n]);
    let (body_type, frozen) = (&p.body_type[..n], &p.frozen[..n]);
    (p.velocity[..n].par_chunks_mut(PARTICLES_PER_TASK))
        .zip(p.angular_momentum[..n].par_chunks_mut(PARTICLES_PER_TASK))
        .enumerate()
        .map(|(c, (velocity, angular_momentum))| {
            let chunk = c * PARTICLES_PER_TASK..c * PARTICLES_PER_TASK + velocity.len();
            let (f, t) = (&force[chunk.clone()], &torque[chunk.clone()]);
            let (kind, frozen) = (&body_type[chunk.clone()], &frozen[chunk.clone()]);
            for (o, (v, l)) in velocity
                .iter_mut()
                .zip(angular_momentum.iter_mut())
                .enumerate()
            {
                if frozen[o] {
                    continue;
                }
                *v += f[o] * steps[kind[o] as usize].kick;
                *l += t[o] * (0.5 * dt);
            }
            all_finite_entries(&position[chunk], velocity, angular_momentum, (f, t))
        })
        .reduce(|| true, |a, b| a && b)
}
