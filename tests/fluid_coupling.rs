//! CFD–DEM coupling against closed forms and published correlations:
//! - terminal settling velocities: Stokes, Schiller–Naumann, and a cube and a
//!   dodecahedron under the Hölzer–Sommerfeld and Ganser correlations (each run for
//!   20–25 relaxation times, so within 1e-5 of the terminal speed);
//! - the pressure drop across a poured bed against Ergun, and its solid fractions
//!   against its volume;
//! - the momentum given back to the fluid equal to what the particles received;
//! - saved states, `talus run`'s fluid frames, and bad inputs and scene keys.
use std::path::Path;

mod common;
use common::read_vtk;

use nalgebra::Vector3;
use talus::Real;
use talus::fluid::shape::{ganser_cd, holzer_sommerfeld_cd};
use talus::fluid::{DragShape, ShapeCorrection};
use talus::scene::{FluidError, Scene, Simulation};

const G: Real = 9.81;

/// One particle of `shape` (TOML), density 2500, at rest in a fluid at rest, falling
/// for `end` seconds in steps of `dt` on a grid of 4 × 4 × 8 cells of 5 cm.
fn falling(shape: &str, fluid: &str, end: Real, dt: Real) -> Simulation {
    let text = format!(
        r#"
[simulation]
dt = {dt}
end_time = {end}
gravity = [0.0, 0.0, -{G}]

[materials.glass]
density = 2500.0
young = 1e7
poisson = 0.3
restitution = 0.5
friction = 0.5

[shapes.grain]
{shape}

[[particles]]
kind = "list"
shape = "grain"
material = "glass"
bodies = [{{ position = [0.1, 0.1, 0.3] }}]

[fluid]
origin = [0.0, 0.0, 0.0]
cell = [0.05, 0.05, 0.05]
cells = [4, 4, 8]
{fluid}
"#
    );
    let scene = Scene::parse(&text, Path::new("falling.toml")).unwrap();
    let mut sim = Simulation::new(&scene);
    while !sim.is_finished() {
        sim.step();
    }
    sim
}

/// The speed at which `drag(v)` carries the buoyant weight `w`, by bisection.
fn terminal(w: Real, drag: impl Fn(Real) -> Real) -> Real {
    let (mut lo, mut hi) = (0.0, 100.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if drag(mid) < w { lo = mid } else { hi = mid }
    }
    0.5 * (lo + hi)
}

fn settling_speed(sim: &Simulation) -> Real {
    -sim.world().particles.velocity[0].z
}

#[test]
fn a_sphere_in_creeping_flow_falls_at_stokes_velocity() {
    // Glass in glycerol: Re ≈ 1e-3; relaxation time ρp d²/(18 μ) = 0.14 ms.
    let (d, rho_f, mu) = (1e-3, 1260.0, 1.0);
    let sim = falling(
        "kind = \"sphere\"\nradius = 5e-4",
        &format!("density = {rho_f}\nviscosity = {mu}\ndrag = \"stokes\""),
        3e-3,
        1.4e-6,
    );
    let stokes = (2500.0 - rho_f) * G * d * d / (18.0 * mu);
    let v = settling_speed(&sim);
    println!(
        "Stokes: {v:.6e} m/s against {stokes:.6e} ({:+.1e})",
        v / stokes - 1.0
    );
    assert!((v / stokes - 1.0).abs() < 1e-5, "{v} against {stokes}");
}

#[test]
fn a_sphere_at_moderate_reynolds_falls_at_the_schiller_naumann_velocity() {
    // Glass (2 mm) in a viscous oil: Re ≈ 10; relaxation time about 10 ms.
    let (d, rho_f, mu): (Real, Real, Real) = (2e-3, 1000.0, 0.02);
    let sim = falling(
        "kind = \"sphere\"\nradius = 1e-3",
        &format!("density = {rho_f}\nviscosity = {mu}\ndrag = \"schiller_naumann\""),
        0.25,
        2e-4,
    );
    let volume = std::f64::consts::PI * d.powi(3) / 6.0;
    let v_t = terminal((2500.0 - rho_f) * volume * G, |v| {
        let re = rho_f * v * d / mu;
        0.5 * rho_f * std::f64::consts::PI * d * d / 4.0 * v * v * 24.0 / re
            * (1.0 + 0.15 * re.powf(0.687))
    });
    let re = rho_f * v_t * d / mu;
    assert!(re > 5.0 && re < 30.0, "Re {re}");
    let v = settling_speed(&sim);
    println!(
        "Schiller–Naumann: {v:.6e} m/s against {v_t:.6e} ({:+.1e}, Re {re:.2})",
        v / v_t - 1.0
    );
    assert!((v / v_t - 1.0).abs() < 1e-5, "{v} against {v_t} (Re {re})");
}

/// The terminal speed of `shape` under Schiller–Naumann with `correction`: the
/// correlation's own drag coefficient of the shape at its pose (Hölzer–Sommerfeld:
/// the crosswise sphericity from the area it shows the flow).
fn shaped(shape: &str, correction: ShapeCorrection, name: &str) {
    let (rho_f, mu): (Real, Real) = (1000.0, 0.02);
    let sim = falling(
        shape,
        &format!(
            "density = {rho_f}\nviscosity = {mu}\ndrag = \"schiller_naumann\"\nshape_correction = \"{name}\""
        ),
        0.25,
        2e-4,
    );
    let w = sim.world();
    let drag_shape = DragShape::of(&w.body_types[0].shape);
    let (d, phi) = (drag_shape.diameter, drag_shape.sphericity);
    // Straight down: the fluid puts no torque on a particle, so it keeps its pose.
    let q = w.particles.orientation[0];
    let shown = drag_shape.projected_area(&q, &Vector3::z());
    let area = std::f64::consts::PI * d * d / 4.0;
    let cd = |re: Real| match correction {
        ShapeCorrection::HolzerSommerfeld => holzer_sommerfeld_cd(re, phi, area / shown),
        _ => ganser_cd(re, phi),
    };
    let weight = (2500.0 - rho_f) * drag_shape.volume * G;
    let v_t = terminal(weight, |v| {
        0.5 * rho_f * area * v * v * cd(rho_f * v * d / mu)
    });
    let v = settling_speed(&sim);
    println!(
        "{name}, ψ {phi:.4}: {v:.6e} m/s against {v_t:.6e} ({:+.1e})",
        v / v_t - 1.0
    );
    assert!((v / v_t - 1.0).abs() < 1e-5, "{name}: {v} against {v_t}");
    // A sphere of the same volume falls faster (by the same correlation).
    let sphere_cd = |re: Real| match correction {
        ShapeCorrection::HolzerSommerfeld => holzer_sommerfeld_cd(re, 1.0, 1.0),
        _ => ganser_cd(re, 1.0),
    };
    let sphere = terminal(weight, |v| {
        0.5 * rho_f * area * v * v * sphere_cd(rho_f * v * d / mu)
    });
    assert!(
        v < 0.97 * sphere,
        "{name}: {v} against the sphere's {sphere}"
    );
}

#[test]
fn a_cube_and_a_dodecahedron_fall_at_their_correlations_velocity() {
    for (correction, name) in [
        (ShapeCorrection::HolzerSommerfeld, "holzer_sommerfeld"),
        (ShapeCorrection::Ganser, "ganser"),
    ] {
        shaped(
            "kind = \"cuboid\"\nsize = [2e-3, 2e-3, 2e-3]",
            correction,
            name,
        );
        shaped(
            "kind = \"platonic\"\nsolid = \"dodecahedron\"\ncircumradius = 1.2e-3",
            correction,
            name,
        );
    }
}

#[test]
fn the_fluid_gets_back_exactly_the_drag_the_particles_received() {
    let mut sim = falling(
        "kind = \"platonic\"\nsolid = \"dodecahedron\"\ncircumradius = 0.02",
        "density = 1.2\nviscosity = 1.8e-5\ndrag = \"di_felice\"\nvelocity = [0.3, -0.2, 2.0]\nupdate_interval = 3",
        0.0,
        1e-4,
    );
    // A particle straddling cells, in a fluid moving differently in each cell.
    let cells = sim.fluid().unwrap().grid.len();
    let velocity: Vec<_> = (0..cells)
        .map(|c| Vector3::new(0.1 * (c % 5) as Real, 0.0, 1.0 + 0.01 * c as Real))
        .collect();
    sim.set_fluid_velocity(&velocity).unwrap();
    sim.edit_world(|w| w.particles.position[0] = nalgebra::Point3::new(0.1, 0.1, 0.2));
    sim.update_fluid();
    sim.take_momentum_source().unwrap();
    let mut received = Vector3::zeros();
    let dt = sim.dt();
    for _ in 0..40 {
        sim.step();
        received += sim.fluid().unwrap().exchange.drag[0] * dt;
    }
    let source = sim.take_momentum_source().unwrap();
    let shares = source.iter().filter(|f| f.norm() > 0.0).count();
    assert!(shares >= 4, "the particle straddles {shares} cells");
    let given: Vector3<Real> = source.iter().sum::<Vector3<Real>>() * (40.0 * dt);
    assert!(
        (given + received).norm() <= 1e-12 * received.norm(),
        "{given:?} against {received:?}"
    );
    // Read again: nothing new.
    assert!(
        sim.take_momentum_source()
            .unwrap()
            .iter()
            .all(|f| f.norm() == 0.0)
    );
}

#[test]
fn fluid_inputs_of_the_wrong_size_or_not_finite_are_refused() {
    let mut sim = falling(
        "kind = \"sphere\"\nradius = 1e-3",
        "density = 1000.0\nviscosity = 1e-3\ndrag = \"gidaspow\"",
        0.0,
        1e-4,
    );
    let cells = sim.fluid().unwrap().grid.len();
    assert_eq!(cells, 128);
    let before = sim.fluid().unwrap().velocity.clone();
    assert_eq!(
        sim.set_fluid_velocity(&[Vector3::zeros(); 5]),
        Err(FluidError::Length {
            what: "fluid velocity",
            got: 5,
            cells
        })
    );
    let mut bad = vec![Vector3::zeros(); cells];
    bad[17].y = Real::NAN;
    assert_eq!(
        sim.set_pressure_gradient(&bad),
        Err(FluidError::NotFinite {
            what: "pressure gradient",
            cell: 17
        })
    );
    assert_eq!(sim.fluid().unwrap().velocity, before);
}

/// The settled bed of 10 000 dodecahedra that `talus bench` ships (poured by
/// talus, circumradius 5 mm, in a box 0.3155 m square), under a fluid of `grid`
/// (the lines of `[fluid]` that place it) with the Gidaspow drag.
fn poured_bed(grid: &str, rho: Real, mu: Real) -> Simulation {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("benches/data");
    let bed = std::fs::read_to_string(dir.join("settled_bed.toml")).unwrap();
    let text =
        format!("{bed}\n[fluid]\n{grid}\ndensity = {rho}\nviscosity = {mu}\ndrag = \"gidaspow\"\n");
    Simulation::new(&Scene::parse(&text, &dir.join("settled_bed.toml")).unwrap())
}

#[test]
fn the_solid_fractions_of_a_poured_bed_add_up_to_its_volume() {
    // Cells of two particle diameters; the grid reaches a cell beyond the box, as
    // some particles press into the walls.
    let h = 0.3155 / 18.0;
    let sim = poured_bed(
        &format!("origin = [-{h}, -{h}, -{h}]\ncell = [{h}, {h}, {h}]\ncells = [20, 20, 7]"),
        1000.0,
        1e-3,
    );
    let fluid = sim.fluid().unwrap();
    let volume = sim.world().particles.len() as Real * sim.world().body_types[0].shape.volume();
    let total = solid_volume(&sim);
    assert!(
        (total / volume - 1.0).abs() < 1e-12,
        "{total} against {volume}"
    );
    // Cells of two diameters are far from uniform: the porosity of the inner cells
    // ranges widely.
    let inner: Vec<Real> = (0..fluid.grid.len())
        .filter(|&c| fluid.grid.centre(c).z > 0.02 && fluid.grid.centre(c).z < 0.06)
        .map(|c| fluid.solid_fraction[c])
        .collect();
    let (lo, hi) = inner.iter().fold((1.0, 0.0), |(lo, hi): (Real, Real), &s| {
        (lo.min(s), hi.max(s))
    });
    assert!(lo < 0.45 && hi > 0.55, "solid fractions {lo}..{hi}");
}

/// Σ solid fraction × cell volume over the fluid's cells.
fn solid_volume(sim: &Simulation) -> Real {
    let fluid = sim.fluid().unwrap();
    fluid
        .solid_fraction
        .iter()
        .enumerate()
        .map(|(c, phi)| phi * fluid.grid.cell_volume(c))
        .sum()
}

#[test]
fn a_poured_bed_on_cylindrical_and_given_cells() {
    let volume = |sim: &Simulation| {
        sim.world().particles.len() as Real * sim.world().body_types[0].shape.volume()
    };
    // A tube about the box's axis out past its corners, 12 annuli of which the outer
    // ones are cut by the walls, 8 sectors: the shares add up to the bed.
    let sim = poured_bed(
        "grid = \"cylindrical\"\nbase = [0.15775, 0.15775, -0.01]\nradius = 0.225\n\
         height = 0.2\ncells = [12, 10, 8]",
        1000.0,
        1e-3,
    );
    let total = solid_volume(&sim);
    assert!(
        (total / volume(&sim) - 1.0).abs() < 1e-12,
        "{total} against {}",
        volume(&sim)
    );
    // The outermost annulus lies beyond the walls but for the corners: nearly empty;
    // the inner ones hold the bed (a solid fraction near 0.6 below its surface).
    let fluid = sim.fluid().unwrap();
    let talus::fluid::FluidGrid::Cylindrical(grid) = &fluid.grid else {
        panic!("cylindrical")
    };
    let of = |i: usize| {
        (0..fluid.grid.len())
            .filter(|&c| grid.cell(c)[0] == i && grid.cell(c)[1] == 2)
            .map(|c| fluid.solid_fraction[c])
            .sum::<Real>()
            / 8.0
    };
    assert!(
        of(11) < 0.1 && of(2) > 0.4 && of(2) < 0.75,
        "{} {}",
        of(11),
        of(2)
    );

    // The structured grid's cells given by their centres and volumes: the same
    // solid fractions (the Voronoi cells of a structured grid's centres are its
    // cells; dodecahedra are cut exactly both ways).
    let h = 0.3155 / 18.0;
    let structured = poured_bed(
        &format!("origin = [-{h}, -{h}, -{h}]\ncell = [{h}, {h}, {h}]\ncells = [20, 20, 7]"),
        1000.0,
        1e-3,
    );
    let grid = &structured.fluid().unwrap().grid;
    let mut csv = String::from("x,y,z,volume\n");
    for c in 0..grid.len() {
        let p = grid.centre(c);
        csv += &format!("{:e},{:e},{:e},{:e}\n", p.x, p.y, p.z, grid.cell_volume(c));
    }
    let file = std::env::temp_dir().join(format!("talus-cells-{}.csv", std::process::id()));
    std::fs::write(&file, csv).unwrap();
    let given = poured_bed(
        &format!("grid = \"cells\"\nfile = \"{}\"", file.display()),
        1000.0,
        1e-3,
    );
    let _ = std::fs::remove_file(&file);
    let (a, b) = (
        &structured.fluid().unwrap().solid_fraction,
        &given.fluid().unwrap().solid_fraction,
    );
    assert_eq!(a.len(), b.len());
    let worst = a
        .iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, Real::max);
    assert!(worst < 1e-12, "largest difference {worst}");
    assert!(a.iter().any(|&x| x > 0.4));
}

/// The pressure drop a 1-D fluid model (the reactor and plug-flow models' grid:
/// slabs across the whole box) takes from talus's momentum source across the
/// poured bed, against Ergun's equation through the slabs' porosities with the
/// volume-equivalent diameter.
///
/// The stand-in for the CFD code: a uniform superficial velocity `U` upward, the
/// interstitial `U / ε` in each slab, and in steady flow the fluid's momentum
/// balance of each slab (model A) `ε A ∆p = −S`, `S` the momentum source. The slabs
/// compared lie inside the bed: above the first one at the floor, below the surface.
#[test]
fn the_pressure_drop_across_a_poured_bed_is_ergun() {
    let (rho, mu, u) = (1000.0, 1e-3, 0.01);
    let h = 0.3155 / 18.0;
    let mut sim = poured_bed(
        &format!("origin = [0.0, 0.0, 0.0]\ncell = [0.3155, 0.3155, {h}]\ncells = [1, 1, 6]"),
        rho,
        mu,
    );
    let fluid = sim.fluid().unwrap();
    let eps: Vec<Real> = fluid.solid_fraction.iter().map(|s| 1.0 - s).collect();
    let velocity: Vec<_> = eps.iter().map(|e| Vector3::new(0.0, 0.0, u / e)).collect();
    sim.set_fluid_velocity(&velocity).unwrap();
    sim.step();
    let source = sim.take_momentum_source().unwrap();
    let (area, slabs) = (0.3155 * 0.3155, 1..4);
    let drop: Real = slabs.clone().map(|k| -source[k].z / (eps[k] * area)).sum();
    // Ergun through the bed's porosity profile, slab by slab (the bed is graded:
    // denser at the floor than under its surface).
    let d = talus::fluid::DragShape::of(&sim.world().body_types[0].shape).diameter;
    let ergun_gradient = |e: Real| {
        150.0 * mu * (1.0 - e).powi(2) * u / (e.powi(3) * d * d)
            + 1.75 * rho * (1.0 - e) * u * u / (e.powi(3) * d)
    };
    let ergun: Real = slabs.clone().map(|k| ergun_gradient(eps[k]) * h).sum();
    println!(
        "slab porosities {:.4} {:.4} {:.4}: ∆p {drop:.4} Pa, Ergun {ergun:.4} Pa",
        eps[1], eps[2], eps[3]
    );
    assert!(eps[1] > 0.35 && eps[3] < 0.65, "{eps:?}");
    assert!((drop / ergun - 1.0).abs() < 0.03, "{drop} against {ergun}");
}

/// A fluidised handful of spheres and dodecahedra, saved between two share updates
/// and restored into a fresh simulation, goes on to the same bits as the run never
/// saved: positions, velocities, the momentum source and the solid fractions.
#[test]
fn a_saved_fluid_state_restores_bit_for_bit() {
    let text = r#"
[simulation]
dt = 2e-5
end_time = 1.0
gravity = [0.0, 0.0, -9.81]

[materials.glass]
density = 2500.0
young = 1e7
poisson = 0.3
restitution = 0.5
friction = 0.5

[shapes.ball]
kind = "sphere"
radius = 0.002

[shapes.dodecahedron]
kind = "platonic"
solid = "dodecahedron"
circumradius = 0.0025

[[wall]]
name = "box"
material = "glass"
geometry = { kind = "box", min = [0.0, 0.0, 0.0], max = [0.03, 0.03, 0.06], open_top = true }

[[particles]]
kind = "lattice"
shape = "ball"
material = "glass"
min = [0.0, 0.0, 0.0]
max = [0.03, 0.03, 0.012]

[[particles]]
kind = "lattice"
shape = "dodecahedron"
material = "glass"
min = [0.0, 0.0, 0.013]
max = [0.03, 0.03, 0.025]

[fluid]
origin = [0.0, 0.0, 0.0]
cell = [0.01, 0.01, 0.01]
cells = [3, 3, 6]
density = 1.2
viscosity = 1.8e-5
drag = "beetstra"
velocity = [0.0, 0.0, 25.0]
update_interval = 5
"#;
    let scene = Scene::parse(text, Path::new("fluidised.toml")).unwrap();
    let mut whole = Simulation::new(&scene);
    let cells = whole.fluid().unwrap().grid.len();
    let swirl: Vec<_> = (0..cells)
        .map(|c| Vector3::new(0.2 * (c % 3) as Real - 0.2, 0.1, 25.0 + 0.1 * c as Real))
        .collect();
    whole.set_fluid_velocity(&swirl).unwrap();
    for _ in 0..17 {
        whole.step();
    }
    let mut w = talus::scene::StateWriter::default();
    whole.write_state(1, &mut w);
    let bytes = w.into_bytes();
    for _ in 0..43 {
        whole.step();
    }
    let mut restored = Simulation::new(&scene);
    restored
        .read_state(1, &mut talus::scene::StateReader::new(&bytes))
        .unwrap();
    for _ in 0..43 {
        restored.step();
    }
    let (a, b) = (whole.world(), restored.world());
    assert!(a.particles.len() > 40);
    assert_eq!(a.particles.position, b.particles.position);
    assert_eq!(a.particles.velocity, b.particles.velocity);
    assert_eq!(
        whole.fluid().unwrap().solid_fraction,
        restored.fluid().unwrap().solid_fraction
    );
    let moving = a.particles.velocity.iter().filter(|v| v.z > 1e-3).count();
    assert!(moving > 0, "the fluid lifts some particles");
    assert_eq!(
        whole.take_momentum_source(),
        restored.take_momentum_source()
    );
}

/// The coupled scene of the face tests: spheres and dodecahedra in a box under
/// an upward gas flow, shares every 5 steps.
fn column_scene() -> Scene {
    Scene::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/scenes/fluid_column.toml"))
        .unwrap()
}

/// Particles removed between two updates of the shares: the others keep their
/// drag, slip and voidage (their rows of the shares go by id, not index), and the
/// state saved then restores.
#[test]
fn removed_particles_leave_the_others_their_fluid() {
    let mut sim = Simulation::new(&column_scene());
    for _ in 0..53 {
        sim.step();
    }
    let (ids, before) = sim.whole_particle_fluid().unwrap();
    let removed = sim.remove_particles(|w, i| w.particles.id[i] % 3 == 1);
    assert!(removed > 40, "{removed}");
    let (kept, after) = sim.whole_particle_fluid().unwrap();
    let expected: Vec<_> = ids
        .iter()
        .zip(&before)
        .filter(|(id, _)| *id % 3 != 1)
        .collect();
    assert_eq!(kept.len(), expected.len());
    assert!(
        after.iter().all(|f| f.voidage < 1.0),
        "every particle in the gas"
    );
    for ((id, f), (k, g)) in expected.iter().zip(kept.iter().zip(&after)) {
        assert_eq!((*id, *f), (k, g));
    }
    let state = sim.snapshot();
    let mut restored = Simulation::new(&column_scene());
    restored.restore(&state).unwrap();
    assert_eq!(restored.whole_particle_fluid().unwrap().1, after);
}

/// The scene of glass beads in a box under an upward water flow, with `fluid` as the
/// `[fluid]` section's keys (after a structured grid's origin and cell size unless
/// they name a `grid`).
/// `[fluid]` of a cylindrical grid about the beads' box (3 annuli out to its
/// corners, 6 slabs, 4 sectors) in water.
const CYLINDER_KEYS: &str = "grid = \"cylindrical\"\nbase = [0.015, 0.015, 0.0]\nradius = 0.0213\n\
    height = 0.06\ncells = [3, 6, 4]\ndensity = 1000.0\nviscosity = 1e-3\ndrag = \"gidaspow\"\n";

fn beads_in_water(fluid: &str) -> String {
    // A structured grid of 1 cm cells unless the keys name another kind.
    let grid = if fluid.contains("grid = ") {
        ""
    } else {
        "origin = [0.0, 0.0, 0.0]\ncell = [0.01, 0.01, 0.01]\n"
    };
    format!(
        r#"
[simulation]
dt = 2e-6
end_time = 0.002
gravity = [0.0, 0.0, -9.81]

[output]
frame_interval = 0.001

[materials.glass]
density = 2500.0
young = 1e7
poisson = 0.3
restitution = 0.5
friction = 0.5

[shapes.ball]
kind = "sphere"
radius = 0.002

[[wall]]
name = "box"
material = "glass"
geometry = {{ kind = "box", min = [0.0, 0.0, 0.0], max = [0.03, 0.03, 0.06], open_top = true }}

[[particles]]
kind = "lattice"
shape = "ball"
material = "glass"
min = [0.0, 0.0, 0.0]
max = [0.03, 0.03, 0.02]

[fluid]
{grid}{fluid}
"#
    )
}

#[test]
fn talus_run_writes_the_fluid_grid_for_paraview() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("fluid_run");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let scene_file = dir.join("beads.toml");
    std::fs::write(
        &scene_file,
        beads_in_water(
            "cells = [3, 3, 6]\ndensity = 1000.0\nviscosity = 1e-3\ndrag = \"di_felice\"\nvelocity = [0.0, 0.0, 0.05]",
        ),
    )
    .unwrap();
    // `talus run --quiet --threads 2 ARGS beads.toml` in `dir`: Ok, or its stderr.
    let run = |args: &[&str]| {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_talus"))
            .current_dir(&dir)
            .args(["run", "--quiet", "--threads", "2"])
            .args(args)
            .arg(&scene_file)
            .output()
            .unwrap();
        if out.status.success() {
            Ok(())
        } else {
            Err(String::from_utf8_lossy(&out.stderr).into_owned())
        }
    };
    run(&["--out", "out"]).unwrap();
    let pvd = std::fs::read_to_string(dir.join("out/fluid.pvd")).unwrap();
    for t in ["0.000000000e0", "1.000000000e-3", "2.000000000e-3"] {
        assert!(pvd.contains(&format!("timestep=\"{t}\"")), "{pvd}");
    }
    let arrays = read_vtk(&dir.join("out/frames/fluid_000002.vti"));
    let get = |n: &str| &arrays.iter().find(|a| a.0 == n).unwrap().1;
    assert_eq!(get("solid_fraction").len(), 54);
    assert_eq!(get("fluid_velocity").len(), 3 * 54);
    // The beads' volume, in single precision; the flow drags them upward.
    let solid: f64 = get("solid_fraction").iter().sum::<f64>() * 1e-6;
    let scene = Scene::load(&scene_file).unwrap();
    let beads =
        scene.world.particles.len() as f64 * 4.0 / 3.0 * std::f64::consts::PI * 0.002f64.powi(3);
    assert!(
        (solid / beads - 1.0).abs() < 1e-5,
        "{solid} against {beads}"
    );
    let lift: f64 = get("particle_drag").chunks(3).map(|v| v[2]).sum();
    assert!(lift > 0.0, "{lift}");
    // Each particle's drag, slip and voidage on its cells in the particle frame: the
    // slip is the uniform flow less the particle's velocity (single precision), the
    // drags sum to the grid's, the voidage lies within the packing's range.
    let particles = read_vtk(&dir.join("out/frames/particles_000002.vtp"));
    let get = |n: &str| &particles.iter().find(|a| a.0 == n).unwrap().1;
    let (id, velocity, slip, drag, voidage) = (
        get("id"),
        get("velocity"),
        get("slip"),
        get("drag"),
        get("voidage"),
    );
    let mut total = 0.0;
    for c in 0..id.len() {
        for k in 0..3 {
            let flow = [0.0, 0.0, 0.05][k];
            assert!((slip[3 * c + k] + velocity[3 * c + k] - flow).abs() < 1e-6);
        }
        assert!(voidage[c] > 0.2 && voidage[c] < 1.0, "{}", voidage[c]);
        if c == 0 || id[c] != id[c - 1] {
            total += drag[3 * c + 2];
        }
    }
    assert!((total / lift - 1.0).abs() < 1e-5, "{total} against {lift}");

    // On a cylindrical grid: points at the cells' middles, with their volumes.
    std::fs::write(&scene_file, beads_in_water(CYLINDER_KEYS)).unwrap();
    run(&["--out", "cylinder"]).unwrap();
    let arrays = read_vtk(&dir.join("cylinder/frames/fluid_000002.vtp"));
    let get = |n: &str| &arrays.iter().find(|a| a.0 == n).unwrap().1;
    assert_eq!(get("solid_fraction").len(), 72);
    let solid: f64 = get("solid_fraction")
        .iter()
        .zip(get("cell_volume"))
        .map(|(phi, v)| phi * v)
        .sum();
    assert!(
        (solid / beads - 1.0).abs() < 1e-5,
        "{solid} against {beads}"
    );
    let volume: f64 = get("cell_volume").iter().sum();
    let tube = std::f64::consts::PI * 0.0213f64.powi(2) * 0.06;
    assert!(
        (volume / tube - 1.0).abs() < 1e-6,
        "{volume} against {tube}"
    );

    // Shares at each communication step: a coupled run's setting, refused here.
    std::fs::write(
        &scene_file,
        beads_in_water(&format!(
            "{CYLINDER_KEYS}update_interval = \"communication\""
        )),
    )
    .unwrap();
    let err = run(&["--out", "refused"]).unwrap_err();
    assert!(
        err.contains("update_interval = \"communication\" needs a coupled run"),
        "{err}"
    );
}

#[test]
fn a_bad_fluid_section_names_its_field() {
    for (keys, field, what) in [
        (
            "cells = [3, 0, 6]\ndensity = 1000.0\nviscosity = 1e-3\ndrag = \"gidaspow\"",
            "fluid.cells",
            "at least 1",
        ),
        (
            "cells = [3, 3, 6]\ndensity = 1000.0\nviscosity = -1e-3\ndrag = \"gidaspow\"",
            "fluid.viscosity",
            "positive",
        ),
        (
            "cells = [3, 3, 6]\ndensity = 1000.0\nviscosity = 1e-3\ndrag = \"ergun\"",
            "beads.toml:",
            "unknown variant `ergun`",
        ),
        (
            "cells = [3, 3, 6]\ndensity = 1000.0\nviscosity = 1e-3\ndrag = \"gidaspow\"\nupdate_interval = 0",
            "fluid.update_interval",
            "at least 1",
        ),
        (
            "cells = [3, 3, 6]\ndensity = 1000.0\nviscosity = 1e-3\ndrag = \"gidaspow\"\nupdate_interval = \"often\"",
            "beads.toml:",
            "\"often\": expected a number of steps or \"communication\"",
        ),
        (
            "cells = [3, 3, 6]\nradius = 0.02\ndensity = 1000.0\nviscosity = 1e-3\ndrag = \"gidaspow\"",
            "fluid.radius",
            "not a key of a cartesian grid",
        ),
        (
            CYLINDER_KEYS.replace("radius = 0.0213\n", "").as_str(),
            "fluid.radius",
            "either radius or radii",
        ),
        (
            CYLINDER_KEYS
                .replace("radius = 0.0213", "radii = [0.01, 0.005, 0.02]")
                .as_str(),
            "fluid.radii",
            "ascending",
        ),
        (
            CYLINDER_KEYS.replace("height = 0.06\n", "").as_str(),
            "fluid.height",
            "needs it",
        ),
        (
            "grid = \"cells\"\nfile = \"no_such_cells.csv\"\ndensity = 1000.0\nviscosity = 1e-3\ndrag = \"gidaspow\"",
            "fluid.file",
            "no_such_cells.csv: cannot read",
        ),
    ] {
        let err = Scene::parse(&beads_in_water(keys), Path::new("beads.toml"))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains(field) && err.contains(what) && err.contains("beads.toml"),
            "{err}"
        );
    }
    // A cells file's errors name its line (comments and blank lines counted).
    let file = std::env::temp_dir().join(format!("talus-bad-cells-{}.csv", std::process::id()));
    for (text, what) in [
        (
            "# cells\nx,y,z,volume\n0,0,0,1e-6\n\n0.01,0,zero,1e-6\n",
            ":5: column 'z': 'zero' is not a number",
        ),
        (
            "x,y,z,volume\n0,0,0,1e-6\n0.01,0,0,-1e-6\n",
            ":3: the volume -0.000001 is not positive",
        ),
        (
            "x,y,z,volume\n0,0,0,1e-6\n# the same again\n0,0,0,1e-6\n",
            ":4: cell 1: the same centre as cell 0",
        ),
        ("x,y,volume\n0,0,1e-6\n", ":1: the header has no column 'z'"),
    ] {
        std::fs::write(&file, text).unwrap();
        let keys = format!(
            "grid = \"cells\"\nfile = \"{}\"\ndensity = 1000.0\nviscosity = 1e-3\ndrag = \"gidaspow\"",
            file.display()
        );
        let err = Scene::parse(&beads_in_water(&keys), Path::new("beads.toml"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("fluid.file") && err.contains(what), "{err}");
    }
    let _ = std::fs::remove_file(&file);
}
