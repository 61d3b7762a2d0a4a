//! The fluid stage: each owned particle's drag and pressure-gradient force from the
//! fluid around it, and the drag's impulse given back to the cells it came from.

use nalgebra::Vector3;
use rayon::prelude::*;

use crate::Real;
use crate::fluid::drag_force;
use crate::world::World;

/// Smallest share of particles one rayon task takes.
const PARTICLES_PER_TASK: usize = 256;

/// Adds the fluid's forces to every owned particle (frozen ones too: they give the
/// fluid their drag, though they do not move) and, for a step (`stepped`), sums the
/// drag's impulse over `dt` into the cells, in particle order. Returns the work the
/// forces do on the particles over `dt` at their present velocities (J; zero
/// without a fluid).
pub(super) fn fluid_forces(world: &mut World, dt: Real, stepped: bool) -> Real {
    let Some(fluid) = world.fluid.as_mut() else {
        return 0.0;
    };
    let p = &mut world.particles;
    let n = p.owned();
    let model = &fluid.model;
    let field = &*fluid;
    let forces: Vec<(Vector3<Real>, Vector3<Real>)> = (0..n)
        .into_par_iter()
        .with_min_len(PARTICLES_PER_TASK)
        .map(|i| {
            let Some(local) = field.local(i, p.id[i], &p.position[i]) else {
                return (Vector3::zeros(), Vector3::zeros());
            };
            // Body types are fixed by the scene; one added since has no drag shape.
            let Some(shape) = model.shapes.get(p.body_type[i] as usize) else {
                return (Vector3::zeros(), Vector3::zeros());
            };
            let slip = local.velocity - p.velocity[i];
            let along = slip.try_normalize(0.0).unwrap_or_else(Vector3::z);
            let factor =
                |re: Real| shape.factor(model.correction, model.law, re, &p.orientation[i], &along);
            let drag = drag_force(
                model.law,
                &model.properties,
                shape.diameter,
                local.voidage,
                slip,
                factor,
            );
            (drag, -local.pressure_gradient * shape.volume)
        })
        .collect();
    let mut impulse = std::mem::take(&mut fluid.exchange.impulse);
    fluid.exchange.drag.clear();
    let mut power = 0.0;
    for (i, (drag, pressure)) in forces.into_iter().enumerate() {
        p.force[i] += drag + pressure;
        power += (drag + pressure).dot(&p.velocity[i]);
        fluid.exchange.drag.push(drag);
        if stepped {
            fluid.weights(i, p.id[i], &p.position[i], |c, w| {
                impulse[c] += drag * (w * dt)
            });
        }
    }
    fluid.exchange.impulse = impulse;
    if stepped {
        fluid.exchange.elapsed += dt;
    }
    power * dt
}
