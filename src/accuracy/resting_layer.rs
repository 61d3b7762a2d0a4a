//! A resting layer's weight on a wall, and its independence of the triangulation.
//!
//! One particle of each of the scene's first kinds, face down and apart, is let go
//! touching a plane under gravity; once its contacts have rung down, the force on
//! the wall must be the layer's weight (the exact static answer). The same layer on
//! the same plane cut into thousands of jittered triangles must feel the same force
//! at every step: a contact patch that spans facet edges is one contact
//! (`engine::cpu::patch`), not a sum that depends on where the edges run.

use nalgebra::{Point3, Vector3};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

use super::impacts::{Feature, aim};
use super::setup;
use crate::Real;
use crate::scene::{Scene, Simulation};
use crate::world::Wall;

/// Contact periods (of the scene's stiffest contact) the layer rests for.
pub const PERIODS: Real = 200.0;
/// Cells across the finely triangulated plane (two triangles each).
pub const FINE_CELLS: usize = 48;

/// What the resting layer showed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RestingLayer {
    /// Mean force on the plane over the last quarter of the rest, over the layer's
    /// weight, less one.
    pub weight_error: Real,
    /// The largest difference of the forces on the coarse and the fine plane at any
    /// step, over the layer's weight.
    pub triangulation_error: Real,
}

/// The resting layer of the scene's first kinds (up to [`super::KINDS_CHECKED`]) on
/// its first wall material; `None` for a scene without a suggested step.
pub fn resting_layer(scene: &Scene) -> Option<RestingLayer> {
    let period = scene.suggested.as_ref()?.period;
    let w = &scene.world;
    let types: Vec<_> = w
        .body_types
        .iter()
        .take(super::KINDS_CHECKED)
        .cloned()
        .collect();
    let r = types
        .iter()
        .map(|t| t.shape.circumradius())
        .fold(0.0, Real::max);
    types.first()?;
    let material = setup::plane_material(scene, 0);
    let g = match w.gravity.norm() {
        g if g > 0.0 => g,
        _ => 9.81,
    };
    let weight: Real = types.iter().map(|t| t.mass * g).sum();
    let layer = |plane: Wall| {
        let mut world = setup::world(scene, |_| {}, types.clone(), vec![plane]);
        world.gravity = Vector3::new(0.0, 0.0, -g);
        let n = types.len() as Real;
        for (k, t) in types.iter().enumerate() {
            let (down, _) = aim(&t.shape, Feature::Face);
            let q = setup::turned_down(&down);
            let x = (k as Real - 0.5 * (n - 1.0)) * 3.0 * r;
            let centre = Point3::new(x, 0.37 * r * k as Real, setup::depth_below(&t.shape, &q));
            world.particles.push(k as u32, centre, q, k as u64);
        }
        Simulation::new(&scene.reference(world))
    };
    let mut coarse = layer(setup::plane(material, r));
    let mut fine = layer(jittered_plane(material, r));
    let steps = (PERIODS * period / scene.dt).ceil() as usize;
    let (mut sum, mut counted, mut apart) = (0.0, 0, 0.0_f64);
    for step in 0..steps {
        coarse.step();
        fine.step();
        let (a, b) = (coarse.world().walls[0].force, fine.world().walls[0].force);
        apart = apart.max((a - b).norm() / weight);
        if 4 * step >= 3 * steps {
            sum -= a.z;
            counted += 1;
        }
    }
    Some(RestingLayer {
        weight_error: sum / (counted.max(1) as Real * weight) - 1.0,
        triangulation_error: apart,
    })
}

/// The plane of [`setup::plane`] cut into [`FINE_CELLS`]² cells of two triangles,
/// its inner vertices moved at random by up to 0.3 of a cell within the plane.
fn jittered_plane(material: usize, r: Real) -> Wall {
    let n = FINE_CELLS;
    let (size, cell) = (40.0 * r, 40.0 * r / n as Real);
    let mut rng = Pcg64::seed_from_u64(48);
    let mut vertices = Vec::with_capacity((n + 1) * (n + 1));
    for j in 0..=n {
        for i in 0..=n {
            let inner = i > 0 && i < n && j > 0 && j < n;
            let mut jitter = || {
                if inner {
                    rng.random_range(-0.3..0.3) * cell
                } else {
                    0.0
                }
            };
            let (dx, dy) = (jitter(), jitter());
            vertices.push(Point3::new(
                -0.5 * size + i as Real * cell + dx,
                -0.5 * size + j as Real * cell + dy,
                0.0,
            ));
        }
    }
    let at = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    let mut triangles = Vec::with_capacity(2 * n * n);
    for j in 0..n {
        for i in 0..n {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            // Diagonals alternate, so that edges run every way under a face.
            if (i + j) % 2 == 0 {
                triangles.extend([[a, b, c], [a, c, d]]);
            } else {
                triangles.extend([[a, b, d], [b, c, d]]);
            }
        }
    }
    Wall::new("fine plane", material, vertices, triangles, 2.0 * r)
}
