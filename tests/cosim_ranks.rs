//! The component on ranks (what `mpirun -np N talus serve` runs; here the ranks are
//! threads talking through a `ThreadExchange`, the same words as over MPI): the
//! same calls on every rank step one decomposed run whose outputs are one
//! process's, states saved on N ranks restore on M ranks or in one process, and a
//! step that diverges goes back on all ranks; a coupled fluid's outputs are one
//! process's.
//!
//! Tolerances: particle states are one process's bits (each particle gathers its
//! contacts in the same order on ranks); wall forces and torques are sums grouped
//! by rank, equal to round-off: 1e-12 of the largest component. So are a coupled
//! fluid's momentum sources (each rank sums its particles' drag impulse); its
//! solid fractions, mean particle velocities and each particle's drag are one
//! process's bits.

use std::path::Path;

use talus::cosim::{Component, CosimError, VarRef};
use talus::engine::exchange::ThreadExchange;
use talus::scene::{FluidState, SimState};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

const DRUM: &str = "examples/drum_fmu/drum.toml";

/// Runs `calls` on a component of `scene` on each of `ranks` threads (on ranks),
/// or in this thread (one process) when `ranks` is 0; the results in rank order.
fn on_ranks<R: Send>(
    ranks: usize,
    scene: &str,
    calls: impl Fn(&mut Component) -> R + Sync,
) -> Vec<R> {
    if ranks == 0 {
        let mut c = Component::instantiate(root(), scene).unwrap();
        return vec![calls(&mut c)];
    }
    std::thread::scope(|s| {
        let handles: Vec<_> = ThreadExchange::group(ranks)
            .into_iter()
            .map(|exchange| {
                let calls = &calls;
                s.spawn(move || {
                    let mut c =
                        Component::instantiate_on_ranks(root(), scene, Box::new(exchange)).unwrap();
                    calls(&mut c)
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    })
}

fn start(c: &mut Component) {
    c.enter_initialization_mode(0.0).unwrap();
    c.exit_initialization_mode().unwrap();
}

fn vector(c: &Component, name: &str) -> Vec<f64> {
    c.get_real_vector(c.variable(name).unwrap()).unwrap()
}

fn integer(c: &Component, name: &str) -> i64 {
    let var = c.variable(name).unwrap();
    let mut out = [0];
    c.get_integer(&[VarRef { var, element: 0 }], &mut out)
        .unwrap();
    out[0]
}

/// Turns the drum at `omega` for each of `steps` communication steps of `h`.
fn turn(c: &mut Component, omega: &[f64], h: f64) {
    let w = c.variable("drum.angular_velocity").unwrap();
    for &o in omega {
        c.set_real_vector(w, &[0.0, o, 0.0]).unwrap();
        let t = vector(c, "time")[0];
        c.do_step(t, h).unwrap();
    }
}

/// What rank 0 reports: the wall's means and end forces, the facet forces, the
/// bed's figures, and the whole state (collective: every rank calls it).
#[derive(Clone, Debug)]
struct Report {
    walls: Vec<f64>,
    facets: Vec<f64>,
    kinetic: f64,
    particles: i64,
    time: f64,
    state: Option<SimState>,
}

fn report(c: &Component) -> Report {
    let walls = [
        "drum.force",
        "drum.torque",
        "drum.force_end",
        "drum.torque_end",
    ]
    .iter()
    .flat_map(|n| vector(c, n))
    .collect();
    Report {
        walls,
        facets: vector(c, "drum.facet_force"),
        kinetic: vector(c, "kinetic_energy")[0],
        particles: integer(c, "particles"),
        time: vector(c, "time")[0],
        state: c.simulation().unwrap().whole_snapshot(),
    }
}

/// A particle's id, position, velocity and orientation.
type ParticleRow = (u64, [f64; 3], [f64; 3], [f64; 4]);

/// Each particle's row, by id.
fn particle_rows(s: &SimState) -> Vec<ParticleRow> {
    let p = &s.particles;
    let mut rows: Vec<_> = (0..p.len())
        .map(|i| {
            (
                p.id[i],
                p.position[i].coords.into(),
                p.velocity[i].into(),
                p.orientation[i].coords.into(),
            )
        })
        .collect();
    rows.sort_by_key(|r| r.0);
    rows
}

/// Asserts that `a` (rank 0 of a run on ranks) is `b` (one process): the
/// particles to the bit, the sums to round-off.
fn assert_same_run(a: &Report, b: &Report) {
    assert_eq!((a.time, a.particles), (b.time, b.particles));
    let (sa, sb) = (a.state.as_ref().unwrap(), b.state.as_ref().unwrap());
    assert_eq!(sa.steps, sb.steps);
    assert!(
        particle_rows(sa) == particle_rows(sb),
        "the particles are one process's"
    );
    for (name, x, y) in [
        ("walls", &a.walls, &b.walls),
        ("facets", &a.facets, &b.facets),
    ] {
        let scale = y.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(scale > 0.0, "{name}: some force");
        for (u, v) in x.iter().zip(y) {
            assert!((u - v).abs() <= 1e-12 * scale, "{name}: {u} against {v}");
        }
    }
    assert!((a.kinetic - b.kinetic).abs() <= 1e-12 * b.kinetic);
}

#[test]
fn the_drum_turned_on_two_and_three_ranks_is_the_drum_of_one_process() {
    let omega = [3.0, 3.0, -2.0, 1.5];
    let steps = |c: &mut Component| {
        start(c);
        turn(c, &omega, 0.01);
        report(c)
    };
    let one = on_ranks(0, DRUM, steps).remove(0);
    assert!(one.particles == 96 && one.state.as_ref().unwrap().steps > 1000);
    for ranks in [2, 3] {
        let reports = on_ranks(ranks, DRUM, steps);
        assert_same_run(&reports[0], &one);
        // Every rank holds the whole run's wall forces and figures.
        for r in &reports[1..] {
            assert!(r.state.is_none() && r.walls == reports[0].walls);
            assert_eq!(
                (r.particles, r.kinetic),
                (one.particles, reports[0].kinetic)
            );
        }
    }
}

#[test]
fn a_state_saved_on_two_ranks_restores_on_three_ranks_and_in_one_process() {
    let saved = on_ranks(2, DRUM, |c| {
        start(c);
        turn(c, &[3.0, 3.0], 0.01);
        let state = c.save_state().unwrap();
        c.state_to_bytes(&state)
    });
    assert_eq!(saved[0], saved[1], "every rank holds the whole state");
    let bytes = &saved[0];
    let resumed = |c: &mut Component| {
        start(c);
        let state = c.state_from_bytes(bytes).unwrap();
        c.restore_state(&state).unwrap();
        assert_eq!(vector(c, "time")[0], 0.02);
        turn(c, &[-2.0, 1.0], 0.01);
        report(c)
    };
    let one = on_ranks(0, DRUM, resumed).remove(0);
    let three = on_ranks(3, DRUM, resumed);
    assert_same_run(&three[0], &one);
    // And the same as never having stopped, in one process.
    let through = on_ranks(0, DRUM, |c| {
        start(c);
        turn(c, &[3.0, 3.0, -2.0, 1.0], 0.01);
        report(c)
    })
    .remove(0);
    assert_same_run(&one, &through);
}

#[test]
fn a_step_that_diverges_on_ranks_goes_back_on_every_rank() {
    let scene = "tests/scenes/overflowing.toml";
    let run = |c: &mut Component| {
        start(c);
        c.do_step(0.0, 0.01).unwrap();
        let before = c.simulation().unwrap().whole_snapshot();
        // The beads reach the floor after about 45 ms.
        let err = c.do_step(0.01, 0.1).unwrap_err();
        assert!(matches!(err, CosimError::Diverged(_)), "{err}");
        let after = c.simulation().unwrap().whole_snapshot();
        c.do_step(0.01, 0.01).unwrap();
        (
            before,
            after,
            vector(c, "time")[0],
            vector(c, "floor.force"),
        )
    };
    let one = on_ranks(0, scene, run).remove(0);
    let two = on_ranks(2, scene, run);
    for (before, after, time, _) in two.iter().chain([&one]) {
        assert_eq!(*time, 0.02);
        if let (Some(before), Some(after)) = (before, after) {
            assert!(before.particles.position == after.particles.position);
            assert!(before.particles.velocity == after.particles.velocity);
            assert_eq!(before.steps, after.steps);
        }
    }
    let sorted = |s: &SimState| {
        let mut x: Vec<_> = (0..s.particles.len())
            .map(|i| (s.particles.id[i], s.particles.position[i]))
            .collect();
        x.sort_by_key(|r| r.0);
        x
    };
    let (a, b) = (two[0].0.as_ref().unwrap(), one.0.as_ref().unwrap());
    assert!(sorted(a) == sorted(b));
    assert_eq!(two[0].3, two[1].3, "every rank the whole floor force");
}

/// Rank 0's readings of the whole world after `steps` steps of `h`: each
/// variable's values.
fn readings(ranks: usize, scene: &str, steps: usize, h: f64, names: &[&str]) -> Vec<Vec<f64>> {
    let run = |c: &mut Component| {
        start(c);
        for k in 0..steps {
            c.do_step(k as f64 * h, h).unwrap();
        }
        names.iter().map(|n| vector(c, n)).collect::<Vec<_>>()
    };
    on_ranks(ranks, scene, run).remove(0)
}

/// Equal to round-off: the whole world's figures are summed in the order rank 0
/// gathered it (by id), one process's in its own.
fn assert_close(a: &[Vec<f64>], b: &[Vec<f64>], names: &[&str]) {
    for ((x, y), name) in a.iter().zip(b).zip(names) {
        for (u, v) in x.iter().zip(y) {
            assert!(
                (u - v).abs() <= 1e-12 * v.abs().max(1e-300),
                "{name}: {u} against {v}"
            );
        }
    }
}

#[test]
fn the_drum_and_bed_figures_on_ranks_are_one_process_figures() {
    let names = ["angle_of_repose", "drive_torque", "shell.facet_force"];
    let drum = "examples/drum/quasi2d.toml";
    let one = readings(0, drum, 4, 0.025, &names);
    assert!(one[0][0] > 0.0 && one[1][0] != 0.0, "{:?}", &one[..2]);
    assert_close(&readings(2, drum, 4, 0.025, &names), &one, &names);
    let names = ["bed_height", "porosity"];
    let bed = "examples/fixed_bed/seed_bed.toml";
    let one = readings(0, bed, 2, 0.05, &names);
    assert!(one[0][0] > 0.0 && one[1][0] > 0.0, "{one:?}");
    assert_close(&readings(3, bed, 2, 0.05, &names), &one, &names);
}

#[test]
fn a_step_whose_outputs_rank_0_cannot_write_fails_on_every_rank() {
    let out = std::env::temp_dir().join(format!("talus-cosim-ranks-out-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let results = on_ranks(2, DRUM, |c| {
        let var = c.variable("output_dir").unwrap();
        c.set_string(&[VarRef { var, element: 0 }], &[out.to_str().unwrap()])
            .unwrap();
        start(c);
        // Rank 0 made the directories; a file where the frames go fails the first frame.
        if c.rank() == Some((0, 2)) {
            std::fs::remove_dir_all(out.join("frames")).unwrap();
            std::fs::write(out.join("frames"), b"not a directory").unwrap();
        }
        let err = c.do_step(0.0, 0.01).unwrap_err();
        (err.to_string(), vector(c, "time")[0])
    });
    assert!(
        matches!(&results[..], [(a, t), (b, u)] if t == u && a.starts_with("output")
        && b.contains("rank 0 could not write")),
        "{results:?}"
    );
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn output_files_rank_0_cannot_create_fail_initialisation_on_every_rank() {
    let file = std::env::temp_dir().join(format!("talus-cosim-ranks-file-{}", std::process::id()));
    std::fs::write(&file, b"a file, not a directory").unwrap();
    let results = on_ranks(2, DRUM, |c| {
        let var = c.variable("output_dir").unwrap();
        c.set_string(&[VarRef { var, element: 0 }], &[file.to_str().unwrap()])
            .unwrap();
        c.enter_initialization_mode(0.0).unwrap();
        let err = c.exit_initialization_mode().unwrap_err().to_string();
        (err, c.mode())
    });
    assert!(
        matches!(&results[..], [(a, m), (b, n)] if m == n && a.starts_with("output")
        && b.contains("rank 0 could not create")),
        "{results:?}"
    );
    let _ = std::fs::remove_file(&file);
}

const COLUMN: &str = "tests/scenes/fluid_column.toml";

/// The gas a coupled code might set at its `k`-th exchange: a side wind of 3 m/s
/// turning with `k` and from cell to cell over an upward 2 m/s, so that the
/// particles cross the ranks' boundaries between two updates of their shares
/// (every 5 DEM steps; 100 per exchange).
fn wind(cells: usize, k: usize) -> Vec<f64> {
    (0..cells)
        .flat_map(|c| {
            let a = 0.7 * k as f64 + 0.3 * c as f64;
            [3.0 * a.cos(), 3.0 * a.sin(), 2.0 + 0.05 * c as f64]
        })
        .collect()
}

/// What rank 0 reads of the column's fluid, and the whole state.
#[derive(Debug)]
struct FluidReport {
    solid_fraction: Vec<f64>,
    particle_velocity: Vec<f64>,
    momentum_source: Vec<f64>,
    particle_fluid: (Vec<u64>, Vec<talus::world::ParticleFluid>),
    state: Option<SimState>,
}

/// Blows `wind` of exchanges `exchanges` through the column, 2 ms each.
fn blow(c: &mut Component, exchanges: std::ops::Range<usize>) -> FluidReport {
    let u = c.variable("fluid.velocity").unwrap();
    let cells = c.fluid_grid().unwrap().len();
    for k in exchanges {
        c.set_real_vector(u, &wind(cells, k)).unwrap();
        c.do_step(k as f64 * 0.002, 0.002).unwrap();
    }
    FluidReport {
        solid_fraction: vector(c, "fluid.solid_fraction"),
        particle_velocity: vector(c, "fluid.particle_velocity"),
        momentum_source: vector(c, "fluid.momentum_source"),
        particle_fluid: c.particle_fluid().unwrap(),
        state: c.simulation().unwrap().whole_snapshot(),
    }
}

/// `a` (rank 0 on ranks) is `b` (one process): particles, fields, each
/// particle's drag, shares and drag of the state to the bit; momentum sources and
/// the state's impulses to 1e-12 of the largest.
fn assert_same_fluid(a: &FluidReport, b: &FluidReport) {
    let (sa, sb) = (a.state.as_ref().unwrap(), b.state.as_ref().unwrap());
    assert_eq!(sa.steps, sb.steps);
    assert!(particle_rows(sa) == particle_rows(sb), "particles");
    assert!(a.solid_fraction == b.solid_fraction, "solid fraction");
    assert!(
        a.particle_velocity == b.particle_velocity,
        "particle velocity"
    );
    assert!(
        a.particle_fluid == b.particle_fluid,
        "each particle's fluid"
    );
    let (fa, fb) = (sa.fluid.as_ref().unwrap(), sb.fluid.as_ref().unwrap());
    // By id: one process stores its particles in the space order, the ranks'
    // gathered state in id order.
    let ids = |s: &SimState| {
        let mut ids = s.particles.id.clone();
        ids.sort_unstable();
        ids
    };
    let rows = |s: &SimState, f: &FluidState| -> Vec<_> {
        ids(s).into_iter().map(|id| f.shares.row_of(id)).collect()
    };
    let drag = |s: &SimState, f: &FluidState| {
        let mut drag: Vec<_> = s.particles.id.iter().zip(&f.exchange.drag).collect();
        drag.sort_unstable_by_key(|e| *e.0);
        drag.into_iter().map(|e| *e.1).collect::<Vec<_>>()
    };
    assert!(rows(sa, fa) == rows(sb, fb) && drag(sa, fa) == drag(sb, fb));
    let flat = |v: &[nalgebra::Vector3<f64>]| v.iter().flat_map(|x| x.iter().copied()).collect();
    for (name, x, y) in [
        ("momentum source", &a.momentum_source, &b.momentum_source),
        (
            "impulse",
            &flat(&fa.exchange.impulse),
            &flat(&fb.exchange.impulse),
        ),
    ] {
        let scale = y.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(scale > 0.0, "{name}: some drag");
        for (u, v) in x.iter().zip(y) {
            assert!((u - v).abs() <= 1e-12 * scale, "{name}: {u} against {v}");
        }
    }
}

#[test]
fn a_coupled_fluid_on_two_and_three_ranks_is_the_fluid_of_one_process() {
    let run = |c: &mut Component| {
        start(c);
        blow(c, 0..8)
    };
    let one = on_ranks(0, COLUMN, run).remove(0);
    let moved = one
        .particle_fluid
        .1
        .iter()
        .filter(|f| f.drag.norm() > 0.0)
        .count();
    assert_eq!(
        moved,
        one.particle_fluid.0.len(),
        "every particle in the gas"
    );
    for ranks in [2, 3] {
        let reports = on_ranks(ranks, COLUMN, run);
        assert_same_fluid(&reports[0], &one);
        // The fields the particles make are the whole run's on every rank.
        for r in &reports[1..] {
            assert!(r.solid_fraction == one.solid_fraction);
        }
    }
}

#[test]
fn a_fluid_state_saved_on_two_ranks_continues_on_three_ranks_and_in_one_process() {
    let saved = on_ranks(2, COLUMN, |c| {
        start(c);
        let report = blow(c, 0..4);
        let state = c.save_state().unwrap();
        (c.state_to_bytes(&state), report.momentum_source)
    });
    assert_eq!(saved[0].0, saved[1].0);
    let (bytes, source) = &saved[0];
    let resumed = |c: &mut Component| {
        start(c);
        let state = c.state_from_bytes(bytes).unwrap();
        c.restore_state(&state).unwrap();
        (vector(c, "fluid.momentum_source"), blow(c, 4..8))
    };
    let through = on_ranks(0, COLUMN, |c| {
        start(c);
        blow(c, 0..8)
    })
    .remove(0);
    let scale = source.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for ranks in [0, 3] {
        let (restored_source, report) = &on_ranks(ranks, COLUMN, resumed)[0];
        // Restored, rank 0 reads the source of the exchange before the save.
        for (u, v) in restored_source.iter().zip(source) {
            assert!(
                (u - v).abs() <= 1e-12 * scale,
                "restored source {u} against {v}"
            );
        }
        assert_same_fluid(report, &through);
    }
}
