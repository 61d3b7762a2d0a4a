//! A coupled fluid on the co-simulation component: its variables sized by the grid,
//! the same numbers as the simulation driven directly, inputs set all or none, the
//! momentum source the mean over each communication step, and saved states.

mod common;

use std::ops::ControlFlow;
use std::path::Path;

use nalgebra::Vector3;
use talus::Real;
use talus::cosim::{Causality, Component, CosimError, VarRef, variables::FMI2_MAX_FLUID_CELLS};
use talus::fmi::fmi2_scalars;
use talus::scene::{Scene, Simulation};

const SCENE: &str = "tests/scenes/fluid_column.toml";

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn column() -> Component {
    Component::instantiate(root(), SCENE).unwrap()
}

fn vector(c: &Component, name: &str) -> Vec<Real> {
    c.get_real_vector(c.variable(name).unwrap()).unwrap()
}

fn set(c: &mut Component, name: &str, values: &[Real]) -> Result<(), CosimError> {
    let var = c.variable(name).unwrap();
    c.set_real_vector(var, values)
}

fn swirl(cells: usize, phase: Real) -> Vec<Real> {
    common::fluid_swirl(cells, phase)
}

fn vec3s(flat: &[Real]) -> Vec<Vector3<Real>> {
    flat.chunks_exact(3)
        .map(Vector3::from_column_slice)
        .collect()
}

#[test]
fn the_fluid_variables_are_sized_by_the_grid_with_their_start_values() {
    let c = column();
    let cells = 54;
    let expect = [
        ("fluid.velocity", Causality::Input, 3, "m/s"),
        ("fluid.pressure_gradient", Causality::Input, 3, "Pa/m"),
        ("fluid.solid_fraction", Causality::Output, 1, "1"),
        ("fluid.particle_velocity", Causality::Output, 3, "m/s"),
        ("fluid.momentum_source", Causality::Output, 3, "N"),
    ];
    for (name, causality, width, unit) in expect {
        let v = &c.variables()[c.variable(name).unwrap()];
        assert_eq!(
            (v.causality, v.size, v.unit, v.array_only),
            (causality, width * cells, Some(unit), false),
            "{name}"
        );
    }
    // Start values: the scene's velocity, the hydrostatic gradient.
    let u = vector(&c, "fluid.velocity");
    let g = vector(&c, "fluid.pressure_gradient");
    for cell in 0..cells {
        assert_eq!(&u[3 * cell..3 * cell + 3], &[0.0, 0.0, 2.0]);
        assert_eq!(&g[3 * cell..3 * cell + 3], &[0.0, 0.0, -9.81 * 1.2]);
    }
    // FMI 2.0 offers the small grid's 13 values per cell as scalars.
    let scalars = fmi2_scalars(c.variables());
    let fluid = scalars
        .iter()
        .filter(|(_, n)| n.starts_with("fluid."))
        .count();
    assert_eq!(fluid, 13 * cells);
    assert!(
        scalars
            .iter()
            .any(|(_, n)| n == "fluid.momentum_source[162]")
    );

    // A grid of more cells than FMI 2.0 takes: arrays only.
    let text = std::fs::read_to_string(root().join(SCENE))
        .unwrap()
        .replace("cells = [3, 3, 6]", "cells = [11, 10, 10]");
    let dir = std::env::temp_dir().join(format!("talus-cosim-fluid-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("big.toml"), text).unwrap();
    let big = Component::instantiate(&dir, "big.toml").unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    const { assert!(1100 > FMI2_MAX_FLUID_CELLS) };
    let v = &big.variables()[big.variable("fluid.velocity").unwrap()];
    assert_eq!((v.size, v.array_only), (3300, true));
    assert!(
        fmi2_scalars(big.variables())
            .iter()
            .all(|(_, n)| !n.starts_with("fluid."))
    );
}

/// The fluid column on a cylindrical grid about the box's axis (3 annuli out to the
/// box's corners, 6 slabs, 4 sectors), its shares computed again at the start of
/// each communication step.
const CYLINDER: &str = "grid = \"cylindrical\"\nbase = [0.015, 0.015, 0.0]\nradius = 0.0213\n\
    height = 0.06\ncells = [3, 6, 4]";

/// The column's scene with `[fluid]`'s grid and update interval replaced, in a
/// directory of its own (removed when the component has read it).
fn column_with(grid: &str, interval: &str) -> (Component, Scene) {
    let text = std::fs::read_to_string(root().join(SCENE))
        .unwrap()
        .replace(
            "origin = [0.0, 0.0, 0.0]\ncell = [0.01, 0.01, 0.01]\ncells = [3, 3, 6]",
            grid,
        )
        .replace("update_interval = 5", interval);
    let dir = std::env::temp_dir().join(format!(
        "talus-cosim-fluid-{}-{}",
        std::process::id(),
        text.len()
    ));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("column.toml"), &text).unwrap();
    let c = Component::instantiate(&dir, "column.toml").unwrap();
    let scene = Scene::load(&dir.join("column.toml")).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    (c, scene)
}

/// The component against the simulation stepped by hand: the same inputs give the
/// same bits of every fluid output, and the momentum source is the mean over the
/// last communication step alone; on the structured grid with shares every 5 steps
/// and on the cylindrical one with shares at each communication step.
#[test]
fn the_component_hands_over_what_the_simulation_computes() {
    let (c, scene) = (column(), Scene::load(&root().join(SCENE)).unwrap());
    hands_over(c, scene, 54, false);
    let (c, scene) = column_with(CYLINDER, "update_interval = \"communication\"");
    hands_over(c, scene, 72, true);
}

fn hands_over(mut c: Component, scene: Scene, cells: usize, each_communication: bool) {
    let first = swirl(cells, 0.0);
    set(&mut c, "fluid.velocity", &first).unwrap();
    c.enter_initialization_mode(0.0).unwrap();
    c.exit_initialization_mode().unwrap();
    assert!(
        vector(&c, "fluid.momentum_source")
            .iter()
            .all(|&x| x == 0.0),
        "no step yet: no mean"
    );

    let mut sim = Simulation::new(&scene);
    sim.set_fluid_velocity(&vec3s(&first)).unwrap();
    sim.initialise();

    let h = 13.0 * sim.dt();
    let second = swirl(cells, 0.7);
    for (k, input) in [&first, &second].into_iter().enumerate() {
        set(&mut c, "fluid.velocity", input).unwrap();
        c.do_step(k as Real * h, h).unwrap();
        sim.set_fluid_velocity(&vec3s(input)).unwrap();
        sim.start_communication_step();
        let at_start = sim.fluid().unwrap().solid_fraction.clone();
        let _ = sim.advance_to((k + 1) as Real * h, |_, _| ControlFlow::<()>::Continue(()));
        let source: Vec<Real> = sim
            .take_momentum_source()
            .unwrap()
            .iter()
            .flat_map(|f| [f.x, f.y, f.z])
            .collect();
        let fluid = sim.fluid().unwrap();
        assert_eq!(vector(&c, "fluid.momentum_source"), source, "step {k}");
        assert_eq!(vector(&c, "fluid.solid_fraction"), fluid.solid_fraction);
        if each_communication {
            // Shares from the start of the step, held through it.
            assert_eq!(fluid.solid_fraction, at_start, "step {k}");
        }
        let mean: Vec<Real> = fluid
            .particle_velocity
            .iter()
            .flat_map(|u| [u.x, u.y, u.z])
            .collect();
        assert_eq!(vector(&c, "fluid.particle_velocity"), mean);
    }
    // Each particle's drag, slip and voidage: the simulation's, bit for bit; the
    // upward gas lifts the bed and each particle reads a voidage in (0, 1].
    let (ids, each) = c.particle_fluid().unwrap();
    let world = sim.world();
    let fluid = sim.fluid().unwrap();
    let mut by_id = world.particles.id[..world.particles.owned()].to_vec();
    by_id.sort_unstable();
    assert_eq!(ids, by_id, "every particle once, in id order");
    for (id, f) in ids.iter().zip(&each) {
        let i = world.particles.index_of(*id).unwrap();
        assert_eq!(*f, fluid.at_particle(&world.particles, i));
        assert!(f.voidage > 0.0 && f.voidage <= 1.0, "{f:?}");
    }
    let lift: Real = each.iter().map(|f| f.drag.z).sum();
    assert!(lift > 0.0, "{lift}");
    // The gas lifts: the particles push down on it, and the solid fills cells.
    let source = vector(&c, "fluid.momentum_source");
    let down: Real = source.chunks_exact(3).map(|f| f[2]).sum();
    assert!(
        down < 0.0,
        "the particles take momentum from the gas: {down}"
    );
    // The solid fractions times the cells' volumes: every particle's volume (the
    // cells cover the box; particles pressed into its walls by a little more).
    let grid = c.fluid_grid().unwrap();
    let solid: Real = vector(&c, "fluid.solid_fraction")
        .iter()
        .enumerate()
        .map(|(k, phi)| phi * grid.cell_volume(k))
        .sum();
    let world = sim.world();
    let volume: Real = (0..world.particles.len())
        .map(|i| {
            world.body_types[world.particles.body_type[i] as usize]
                .shape
                .volume()
        })
        .sum();
    assert!(
        (solid / volume - 1.0).abs() < 1e-3,
        "{solid} against {volume}"
    );
}

#[test]
fn bad_fluid_inputs_are_refused_and_change_nothing() {
    let mut c = column();
    c.enter_initialization_mode(0.0).unwrap();
    c.exit_initialization_mode().unwrap();
    let before = vector(&c, "fluid.pressure_gradient");
    let mut bad = swirl(54, 0.0);
    bad[100] = Real::NAN;
    let err = set(&mut c, "fluid.pressure_gradient", &bad).unwrap_err();
    assert!(
        err.to_string().contains("fluid.pressure_gradient") && err.to_string().contains("NaN"),
        "{err}"
    );
    assert_eq!(vector(&c, "fluid.pressure_gradient"), before);
    let solid = c.variable("fluid.solid_fraction").unwrap();
    let err = c
        .set_real(
            &[VarRef {
                var: solid,
                element: 3,
            }],
            &[0.5],
        )
        .unwrap_err();
    assert!(err.to_string().contains("cannot be set"), "{err}");
    let err = c
        .set_real(
            &[VarRef {
                var: solid,
                element: 54,
            }],
            &[0.5],
        )
        .unwrap_err();
    assert!(err.to_string().contains("element 54"), "{err}");
}

#[test]
fn a_restored_state_steps_to_the_same_fluid_outputs() {
    let mut c = column();
    c.enter_initialization_mode(0.0).unwrap();
    c.exit_initialization_mode().unwrap();
    let h = 7e-5 * 3.0;
    set(&mut c, "fluid.velocity", &swirl(54, 0.3)).unwrap();
    c.do_step(0.0, h).unwrap();
    let saved = c.save_state().unwrap();
    let bytes = c.state_to_bytes(&saved);
    set(&mut c, "fluid.velocity", &swirl(54, 1.1)).unwrap();
    c.do_step(h, h).unwrap();
    let outputs = |c: &Component| {
        [
            "fluid.momentum_source",
            "fluid.solid_fraction",
            "fluid.particle_velocity",
            "fluid.velocity",
        ]
        .map(|n| vector(c, n))
    };
    let first = outputs(&c);
    let state = c.state_from_bytes(&bytes).unwrap();
    c.restore_state(&state).unwrap();
    assert_eq!(
        vector(&c, "fluid.velocity"),
        swirl(54, 0.3),
        "the inputs go back too"
    );
    set(&mut c, "fluid.velocity", &swirl(54, 1.1)).unwrap();
    c.do_step(h, h).unwrap();
    assert_eq!(outputs(&c), first);
}
