//! Coulomb friction: the shipped sliding-cuboid example, run as it is. A cuboid
//! launched at v₀ = 1 m/s on a floor with μ = 0.8 decelerates at μg and stops after
//! v₀² / (2 μ g) = 63.71 mm; the floor carries its weight, and the friction force is
//! μ times it while it slides.

use std::path::Path;

use talus::scene::{Scene, Simulation};

#[test]
fn sliding_cuboid_stops_after_the_coulomb_distance() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/sliding_cuboid/scene.toml");
    let scene = Scene::load(&path).unwrap();
    let mut sim = Simulation::new(&scene);
    let x0 = sim.world().particles.position[0].x;
    let (mu, g) = (0.8, 9.81);
    let weight = sim.world().body_types[0].mass * g;
    // Impulses on the floor while the cuboid slides (after the first 10 ms, in which
    // it settles onto the floor from its start at zero overlap).
    let (mut tangential, mut normal, mut span) = (0.0, 0.0, 0.0);
    while !sim.is_finished() {
        sim.step();
        let v = sim.world().particles.velocity[0].x;
        if sim.time() > 0.01 && v > 0.05 {
            let f = sim.world().walls[0].force;
            tangential += f.x * scene.dt;
            normal -= f.z * scene.dt;
            span += scene.dt;
        }
    }
    let ratio = tangential / normal;
    let mean_normal = normal / span;
    assert!(
        (mean_normal / weight - 1.0).abs() < 0.01,
        "normal force {mean_normal}"
    );
    let worst_ratio = (ratio / mu - 1.0).abs();
    let distance = sim.world().particles.position[0].x - x0;
    let expected = 1.0 / (2.0 * mu * g);
    println!(
        "stopped after {:.3} mm (expected {:.3} mm); mean friction/normal within {:.2} % of μ",
        distance * 1e3,
        expected * 1e3,
        100.0 * worst_ratio
    );
    assert!(sim.world().particles.velocity[0].norm() < 1e-3);
    assert!(
        (distance / expected - 1.0).abs() < 0.02,
        "distance {distance}"
    );
    assert!(worst_ratio < 0.01);
}
