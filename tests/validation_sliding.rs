//! Validation 2: a cuboid moved over flat walls meshed at different resolutions
//! (primary seed, section 3.2, Table 2: edge 25 mm, ρ = 1500 kg/m³, E = 1 MPa,
//! ν = 0.1, μ = 0.8, e = 0.1). λ is the ratio of the facet size to the cuboid's edge,
//! from 0.5 (facets half the cuboid) to 8; the meshes are irregular (interior
//! vertices jittered), so facet edges cross the contact at every angle.
//!
//! The cuboid is tilted (an edge and part of a face in contact) and pressed to a fixed
//! depth, then moved along the wall in steps of 0.1 mm over 60 mm; at each position the
//! engine computes the contact force. On a flat wall the exact force does not depend
//! on the position, nor on the mesh: the test asks for the force-displacement curves
//! of all meshes to agree within 1 % and to stay flat (no spikes where the contact
//! crosses facet edges or vertices).

use nalgebra::{Point3, UnitQuaternion, Vector3};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use talus::contact::Material;
use talus::engine::{Backend, CpuBackend};
use talus::geometry::{Shape, generators};
use talus::world::{BodyType, Wall, World};

const EDGE: f64 = 0.025;

/// A square wall z = 0 of side `side` meshed with cells of size `lambda · EDGE`,
/// interior vertices jittered by up to 30 % of a cell.
fn wall(lambda: f64, side: f64, seed: u64) -> Wall {
    let n = ((side / (lambda * EDGE)).round() as usize).max(1);
    let h = side / n as f64;
    let mut rng = Pcg64::seed_from_u64(seed);
    let mut vertices = Vec::new();
    for i in 0..=n {
        for j in 0..=n {
            let interior = i > 0 && i < n && j > 0 && j < n;
            let mut jitter = || {
                if interior {
                    rng.random_range(-0.3..0.3) * h
                } else {
                    0.0
                }
            };
            vertices.push(Point3::new(
                -side / 2.0 + h * i as f64 + jitter(),
                -side / 2.0 + h * j as f64 + jitter(),
                0.0,
            ));
        }
    }
    let id = |i: usize, j: usize| (i * (n + 1) + j) as u32;
    let mut triangles = Vec::new();
    for i in 0..n {
        for j in 0..n {
            // Alternate the diagonal so that facet edges run in several directions.
            if (i + j) % 2 == 0 {
                triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            } else {
                triangles.push([id(i, j), id(i + 1, j), id(i, j + 1)]);
                triangles.push([id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
    }
    Wall::new("floor", 0, vertices, triangles, 2.0 * EDGE)
}

/// Normal force on the cuboid at each position of the sweep.
fn sweep(lambda: f64) -> Vec<Vector3<f64>> {
    let m = Material {
        name: "cuboid".into(),
        density: 1500.0,
        young: 1e6,
        poisson: 0.1,
        restitution: 0.1,
        friction: 0.8,
        rolling_friction: 0.0,
        rolling_damping: 0.0,
    };
    let shape = Shape::Polyhedron(std::sync::Arc::new(
        generators::cuboid(EDGE, EDGE, EDGE).unwrap(),
    ));
    let mut world = World {
        body_types: vec![BodyType::new(shape, &m, 0)],
        materials: vec![m],
        walls: vec![wall(lambda, 0.4, 5)],
        gravity: Vector3::zeros(),
        ..World::default()
    };
    // Tilted by 20° about x and 10° about y: a vertex region and parts of two edges
    // in contact, pressed 1 mm deep.
    let q = UnitQuaternion::from_euler_angles(0.35, 0.17, 0.05);
    let body = world.body_types[0].shape.as_polyhedron().unwrap().clone();
    let lowest = body
        .vertices()
        .iter()
        .map(|v| (q * v.coords).z)
        .fold(f64::INFINITY, f64::min);
    world
        .particles
        .push(0, Point3::new(-0.03, 0.011, -lowest - 1e-3), q, 1);
    let (mut engine, engine_dt) = (CpuBackend::default(), 1e-5);
    (0..=600)
        .map(|k| {
            world.particles.position[0].x = -0.03 + 1e-4 * k as f64;
            engine.initialise(&mut world, engine_dt);
            world.particles.force[0]
        })
        .collect()
}

#[test]
fn force_displacement_does_not_depend_on_the_wall_mesh() {
    let reference = sweep(1.0);
    let scale = reference[0].norm();
    assert!(scale > 0.0);
    for lambda in [0.5, 1.0, 2.0, 4.0, 8.0] {
        let forces = if lambda == 1.0 {
            reference.clone()
        } else {
            sweep(lambda)
        };
        let across = forces
            .iter()
            .zip(&reference)
            .map(|(f, r)| (f - r).norm())
            .fold(0.0, f64::max)
            / scale;
        let along = forces
            .iter()
            .map(|f| (f - forces[0]).norm())
            .fold(0.0, f64::max)
            / scale;
        println!(
            "λ = {lambda}: force {:.6e} N, largest difference to λ = 1: {across:.2e}, \
             largest change along the sweep: {along:.2e}",
            forces[0].norm()
        );
        assert!(across < 0.01, "λ = {lambda}: meshes disagree by {across}");
        assert!(
            along < 0.01,
            "λ = {lambda}: the force varies by {along} along the sweep"
        );
    }
}
