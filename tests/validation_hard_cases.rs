//! Validation 5, hard cases: a fast impact on a wall thinner than the particle does not
//! tunnel; a pile with a size ratio of 10 settles without losing particles (1000
//! dodecahedra coming to rest: `tests/validation_pile.rs`).

mod common;

use std::path::Path;

use common::settle;
use talus::scene::{Scene, Simulation};

const MATERIALS: &str = r#"
[materials.pla]
density = 1500.0
young = 1e6
poisson = 0.1
restitution = 0.3
friction = 0.5

[materials.steel]
density = 7800.0
young = 2e11
poisson = 0.3
restitution = 0.3
friction = 0.5
"#;

/// A dodecahedron (circumradius 5 mm) at 20 m/s onto a plate 1 mm thick (a closed
/// thin box, facets facing out), at the suggested step: it bounces off the top face.
#[test]
fn a_fast_impact_does_not_tunnel_through_a_thin_plate() {
    let text = format!(
        r#"
[simulation]
dt = "auto"
end_time = 0.002
gravity = [0.0, 0.0, 0.0]
{MATERIALS}
[shapes.dodecahedron]
kind = "platonic"
solid = "dodecahedron"
circumradius = 0.005

[[wall]]
name = "plate"
material = "steel"
geometry = {{ kind = "mesh", file = "plate.stl" }}

[[particles]]
kind = "list"
shape = "dodecahedron"
material = "pla"
bodies = [{{ position = [0.0, 0.0, 0.0065], rotation = [0.3, 0.2, 0.1], velocity = [0.0, 0.0, -20.0] }}]
"#
    );
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("thin_plate");
    std::fs::create_dir_all(&dir).unwrap();
    // The plate: the outside of the box [-5, 5] cm × [-5, 5] cm × [-1, 0] mm.
    let plate = talus::geometry::surfaces::box_inside(
        [-0.05, -0.05, -0.001].into(),
        [0.05, 0.05, 0.0].into(),
        false,
    )
    .unwrap()
    .flipped();
    let triangles: Vec<[usize; 3]> = plate
        .triangles
        .iter()
        .map(|t| t.map(|v| v as usize))
        .collect();
    talus::geometry::mesh_io::write_stl(&dir.join("plate.stl"), &plate.vertices, &triangles)
        .unwrap();
    let scene = Scene::parse(&text, &dir.join("scene.toml")).unwrap();
    let mut sim = Simulation::new(&scene);
    let mut lowest: f64 = 1.0;
    while !sim.is_finished() {
        sim.step();
        lowest = lowest.min(sim.world().particles.position[0].z);
    }
    let v = sim.world().particles.velocity[0];
    println!(
        "dt = {:.3e} s: lowest centroid {:.3} mm, rebound velocity {v}",
        scene.dt,
        lowest * 1e3
    );
    assert!(v.z > 0.0, "did not bounce: {v}");
    assert!(sim.world().particles.position[0].z > 0.0);
    // The centroid never came within half an inscribed radius of the plate.
    assert!(lowest > 0.002, "lowest centroid {lowest}");
}

/// A size ratio of 10: eight dodecahedra of circumradius 10 mm and 150 spheres of
/// radius 1 mm poured together into a box come to rest; no sphere ends inside a
/// dodecahedron (the grid hierarchy finds every small–large pair), none leaves.
#[test]
fn a_pile_with_a_size_ratio_of_ten_settles() {
    let text = format!(
        r#"
[simulation]
dt = "auto"
end_time = 3.0
seed = 5
settle = {{ max_speed = 1e-3, hold = 0.02 }}

[contact]
regularisation = 0.5
{MATERIALS}
[shapes.large]
kind = "platonic"
solid = "dodecahedron"
circumradius = 0.01

[shapes.small]
kind = "sphere"
radius = 0.001

[[wall]]
name = "box"
material = "steel"
geometry = {{ kind = "box", min = [0.0, 0.0, 0.0], max = [0.05, 0.05, 0.2] }}

[[particles]]
kind = "lattice"
shape = "large"
material = "pla"
min = [0.0, 0.0, 0.0]
max = [0.05, 0.05, 0.05]
spacing = 0.022
count = 8

[[particles]]
kind = "lattice"
shape = "small"
material = "pla"
min = [0.002, 0.002, 0.05]
max = [0.048, 0.048, 0.07]
spacing = 0.0022
count = 150
"#
    );
    let sim = settle(&text, [0.0; 3], [0.05, 0.05, 0.2], 3.0, true);
    let w = sim.world();
    let p = &w.particles;
    let large = w.body_types[p.body_type[0] as usize]
        .shape
        .as_polyhedron()
        .unwrap();
    for i in 0..p.len() {
        if p.body_type[i] == p.body_type[0] {
            continue;
        }
        for k in 0..p.len() {
            if p.body_type[k] != p.body_type[0] {
                continue;
            }
            let pose = nalgebra::Isometry3::from_parts(p.position[k].into(), p.orientation[k]);
            let x = pose.inverse_transform_point(&p.position[i]);
            let inside = large
                .planes()
                .iter()
                .all(|pl| pl.normal.dot(&x.coords) < pl.offset);
            assert!(!inside, "sphere {i} ended inside dodecahedron {k}");
        }
    }
}

/// Regression: a dodecahedron dropped on a floor comes to rest on a face. Before the
/// contact area damped rocking (`contact::rocking_damping`), it rocked on its face at
/// a few cm/s indefinitely, with or without friction, since the normal dashpot at the
/// overlap's centroid sees no normal velocity when a body rocks about that point; and
/// before twisting friction (`contact::twisting_friction`) it kept spinning about the
/// vertical at 0.9 rad/s.
#[test]
fn a_polyhedron_dropped_on_a_floor_stops_rocking() {
    for friction in [0.0, 0.5] {
        let text = format!(
            r#"
[simulation]
dt = "auto"
end_time = 0.3
[contact]
regularisation = 0.5
[materials.pla]
density = 1500.0
young = 1e6
poisson = 0.1
restitution = 0.3
friction = {friction}
[shapes.dodecahedron]
kind = "platonic"
solid = "dodecahedron"
circumradius = 0.005
[[wall]]
name = "floor"
material = "pla"
geometry = {{ kind = "plane", centre = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0], size = 0.1 }}
[[particles]]
kind = "list"
shape = "dodecahedron"
material = "pla"
bodies = [{{ position = [0.0, 0.0, 0.0055], rotation = [0.3, 0.5, 0.1] }}]
"#
        );
        let scene = Scene::parse(&text, Path::new("drop.toml")).unwrap();
        let mut sim = Simulation::new(&scene);
        while !sim.is_finished() {
            sim.step();
        }
        let ke = sim.world().kinetic_energy();
        let weight = sim.world().body_types[0].mass * 9.81;
        println!("friction {friction}: kinetic energy after 0.3 s {ke:.2e} J");
        assert!(ke < 1e-12, "friction {friction}: still moving, {ke} J");
        assert!((sim.world().walls[0].force.z / -weight - 1.0).abs() < 1e-3);
    }
}
