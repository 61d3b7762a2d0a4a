//! The co-simulation component: life cycle, misuse, communication steps, momentum
//! handed across the interface, torque response, and saved states.

use std::path::Path;

use nalgebra::Vector3;
use talus::cosim::{Component, CosimError, Mode, VarRef};

fn drum(file: &str) -> Component {
    Component::instantiate(
        Path::new(env!("CARGO_MANIFEST_DIR")),
        &format!("examples/drum_fmu/{file}"),
    )
    .unwrap()
}

fn started(file: &str) -> Component {
    let mut c = drum(file);
    c.enter_initialization_mode(0.0).unwrap();
    c.exit_initialization_mode().unwrap();
    c
}

fn set_spin(c: &mut Component, omega_y: f64) {
    let w = c.variable("drum.angular_velocity").unwrap();
    c.set_real_vector(w, &[0.0, omega_y, 0.0]).unwrap();
}

fn vector(c: &Component, name: &str) -> Vec<f64> {
    c.get_real_vector(c.variable(name).unwrap()).unwrap()
}

fn time(c: &Component) -> f64 {
    vector(c, "time")[0]
}

#[test]
fn the_variable_table_names_inputs_outputs_and_units() {
    let c = drum("drum.toml");
    let names: Vec<&str> = c.variables().iter().map(|v| v.name.as_str()).collect();
    for n in [
        "time",
        "scene",
        "dt",
        "output_dir",
        "threads",
        "backend",
        "drum.velocity",
        "drum.angular_velocity",
        "drum.force",
        "drum.torque",
        "drum.force_end",
        "drum.torque_end",
        "drum.power",
        "drum.vertices",
        "drum.facet_force",
        "particles",
        "contacts",
        "kinetic_energy",
    ] {
        assert!(names.contains(&n), "{n} missing from {names:?}");
    }
    let torque = &c.variables()[c.variable("drum.torque").unwrap()];
    assert_eq!(torque.unit, Some("N.m"));
    assert_eq!(torque.size, 3);
    assert!(!torque.description.is_empty());
}

#[test]
fn calls_out_of_order_are_refused_and_change_nothing() {
    let mut c = drum("drum.toml");
    let err = c.do_step(0.0, 1e-3).unwrap_err();
    assert!(matches!(err, CosimError::WrongMode { .. }), "{err}");
    assert!(err.to_string().contains("instantiated"), "{err}");
    let force = c.variable("drum.force").unwrap();
    assert!(matches!(
        c.get_real_vector(force),
        Err(CosimError::WrongMode { .. })
    ));
    assert!(matches!(
        c.exit_initialization_mode(),
        Err(CosimError::WrongMode { .. })
    ));
    assert_eq!(c.mode(), Mode::Instantiated);

    // Inputs: non-finite values are refused, the old value stays.
    let w = c.variable("drum.angular_velocity").unwrap();
    c.set_real_vector(w, &[0.0, 2.0, 0.0]).unwrap();
    for bad in [f64::NAN, f64::INFINITY] {
        assert!(matches!(
            c.set_real_vector(w, &[0.0, bad, 0.0]),
            Err(CosimError::BadValue { .. })
        ));
    }
    assert_eq!(c.get_real_vector(w).unwrap(), vec![0.0, 2.0, 0.0]);
    // Outputs cannot be set, unknown variables are named.
    assert!(c.set_real_vector(force, &[1.0, 2.0, 3.0]).is_err());
    assert!(matches!(
        c.variable("nope"),
        Err(CosimError::UnknownVariable(_))
    ));
    let out_of_range = VarRef { var: w, element: 3 };
    assert!(c.set_real(&[out_of_range], &[1.0]).is_err());
    assert!(
        c.set_real(
            &[VarRef {
                var: 10_000,
                element: 0
            }],
            &[1.0]
        )
        .is_err()
    );
    // A non-positive time step is refused.
    let dt = c.variable("dt").unwrap();
    assert!(c.set_real_vector(dt, &[0.0]).is_err());
    assert!(c.set_real_vector(dt, &[-1e-5]).is_err());

    c.enter_initialization_mode(0.0).unwrap();
    c.exit_initialization_mode().unwrap();
    for (t, h) in [
        (0.0, 0.0),
        (0.0, -1e-3),
        (0.0, f64::NAN),
        (0.0, f64::INFINITY),
        (0.5, 1e-3),
        (f64::NAN, 1e-3),
    ] {
        let err = c.do_step(t, h).unwrap_err();
        assert!(matches!(err, CosimError::BadStep(_)), "({t}, {h}): {err}");
    }
    assert_eq!(time(&c), 0.0);
    assert_eq!(c.mode(), Mode::Step);
    // Parameters are fixed once running.
    assert!(c.set_real_vector(dt, &[1e-5]).is_err());
    c.terminate().unwrap();
    assert!(c.do_step(0.0, 1e-3).is_err());
    c.reset();
    assert_eq!(c.mode(), Mode::Instantiated);
    assert_eq!(
        c.get_real_vector(w).unwrap(),
        vec![0.0, 0.0, 0.0],
        "reset restores start values"
    );
}

/// Communication steps land exactly on t + h, however h relates to dt.
#[test]
fn steps_land_on_the_communication_points() {
    let mut c = started("drum.toml");
    let dt = vector(&c, "dt")[0];
    let mut t = 0.0;
    for h in [0.37 * dt, 2.5 * dt, 1e-3, dt] {
        c.do_step(t, h).unwrap();
        t += h;
        assert_eq!(time(&c), t);
    }
    let sim = c.simulation().unwrap();
    // 1 + 3 + ceil(1e-3/dt) + 1 DEM steps.
    assert_eq!(sim.steps, 1 + 3 + (1e-3 / dt).ceil() as u64 + 1);
    assert_eq!(sim.dt(), dt, "the shortened last step does not change dt");
}

/// The mean wall force over a step is the momentum the particles exchanged with the
/// wall: Σ m Δv = M g h + F̄ h, to round-off.
#[test]
fn mean_wall_force_is_the_impulse_the_particles_received() {
    let mut c = started("drum.toml");
    set_spin(&mut c, 3.0);
    let momentum = |c: &Component| -> (Vector3<f64>, f64) {
        let w = c.simulation().unwrap().world();
        let p = &w.particles;
        (0..p.len()).fold((Vector3::zeros(), 0.0), |(sum, m), i| {
            let mass = w.body_types[p.body_type[i] as usize].mass;
            (sum + p.velocity[i] * mass, m + mass)
        })
    };
    let mut t = 0.0;
    for h in [0.05, 0.013, 0.1] {
        let (before, mass) = momentum(&c);
        c.do_step(t, h).unwrap();
        t += h;
        let (after, _) = momentum(&c);
        let f = Vector3::from_column_slice(&vector(&c, "drum.force"));
        let gravity = Vector3::new(0.0, 0.0, -9.81) * mass;
        // The wall pushes the particles with -F (F is the force on the wall).
        let residual = (after - before) - (gravity - f) * h;
        let scale = mass * 9.81 * h;
        assert!(
            residual.norm() < 1e-9 * scale,
            "h = {h}: residual {residual:?} of {scale}"
        );
    }
    // Mean and end-of-step values are different things in a moving bed.
    assert_ne!(vector(&c, "drum.force"), vector(&c, "drum.force_end"));
}

/// The bed lifted by the turning drum pulls back: the torque on the drum opposes the
/// rotation, and turns sign with it; an empty drum feels nothing.
#[test]
fn drum_torque_follows_the_rotation() {
    let mut empty = started("empty_drum.toml");
    set_spin(&mut empty, 3.0);
    empty.do_step(0.0, 0.05).unwrap();
    assert_eq!(vector(&empty, "drum.torque"), vec![0.0; 3]);
    assert_eq!(vector(&empty, "drum.force"), vec![0.0; 3]);

    let mut c = started("drum.toml");
    // Settle, then turn one way and the other.
    c.do_step(0.0, 0.3).unwrap();
    let mut t = 0.3;
    let torque = |c: &mut Component, omega: f64, t: &mut f64| {
        set_spin(c, omega);
        let mut sum = 0.0;
        for _ in 0..10 {
            c.do_step(*t, 0.05).unwrap();
            *t += 0.05;
            sum += vector(c, "drum.torque")[1];
        }
        sum / 10.0
    };
    let forward = torque(&mut c, 3.0, &mut t);
    let backward = torque(&mut c, -3.0, &mut t);
    // Order of magnitude: the bed's weight (0.64 N) times an offset of a few cm.
    let weight = 96.0 * 6.7021e-4 * 9.81;
    assert!(forward < -0.05 * weight * 0.06, "forward torque {forward}");
    assert!(
        backward > 0.05 * weight * 0.06,
        "backward torque {backward}"
    );
    assert!(forward.abs() < weight * 0.06 && backward.abs() < weight * 0.06);
    // The drive delivers power to the bed.
    assert!(vector(&c, "drum.power")[0] > 0.0);
}

fn outputs(c: &Component) -> Vec<f64> {
    [
        "drum.force",
        "drum.torque",
        "drum.force_end",
        "drum.torque_end",
        "kinetic_energy",
        "time",
    ]
    .iter()
    .flat_map(|n| vector(c, n))
    .collect()
}

fn bits(x: &[f64]) -> Vec<u64> {
    x.iter().map(|v| v.to_bits()).collect()
}

#[test]
fn restoring_a_state_and_stepping_again_gives_the_same_bits() {
    let mut c = started("drum.toml");
    set_spin(&mut c, 3.0);
    c.do_step(0.0, 0.1).unwrap();
    let saved = c.save_state().unwrap();
    let bytes = c.state_to_bytes(&saved);
    c.do_step(0.1, 0.05).unwrap();
    let first = outputs(&c);
    c.restore_state(&saved).unwrap();
    assert_eq!(time(&c), 0.1);
    c.do_step(0.1, 0.05).unwrap();
    assert_eq!(bits(&outputs(&c)), bits(&first), "in-memory rollback");

    // Through bytes into a fresh instance.
    let mut fresh = started("drum.toml");
    let state = fresh.state_from_bytes(&bytes).unwrap();
    fresh.restore_state(&state).unwrap();
    assert_eq!(time(&fresh), 0.1);
    fresh.do_step(0.1, 0.05).unwrap();
    assert_eq!(bits(&outputs(&fresh)), bits(&first), "through bytes");

    // Garbage, truncated bytes and a state of another scene are refused; nothing changes.
    let before = outputs(&fresh);
    for bad in [&b"garbage"[..], &bytes[..bytes.len() / 2], &[]] {
        assert!(matches!(
            fresh.state_from_bytes(bad),
            Err(CosimError::State(_))
        ));
    }
    let mut flipped = bytes.clone();
    flipped[9] ^= 0xff; // the scene fingerprint
    assert!(fresh.state_from_bytes(&flipped).is_err());
    let empty = started("empty_drum.toml");
    assert!(empty.state_from_bytes(&bytes).is_err());
    assert_eq!(bits(&outputs(&fresh)), bits(&before));
}

#[test]
fn every_damaged_state_is_refused() {
    let mut c = started("drum.toml");
    c.do_step(0.0, 0.02).unwrap();
    let bytes = c.state_to_bytes(&c.save_state().unwrap());
    // 300 single flipped bytes spread over the whole state (the experiment
    // accepted 299 of them before states carried a checksum): all refused, and
    // named as damage, not as another scene or garbage. Then every truncation
    // length in steps of 97 bytes.
    let mut refused = 0;
    for k in 0..300 {
        let at = (k * 7919 + 13) % bytes.len();
        let mut flipped = bytes.clone();
        flipped[at] ^= 1 << (k % 8);
        match c.state_from_bytes(&flipped) {
            Err(CosimError::State(_)) => refused += 1,
            other => panic!("byte {at} flipped: {other:?}"),
        }
        let err = c.state_from_bytes(&flipped).unwrap_err().to_string();
        assert!(
            at < 8 || err.contains("damaged state"),
            "byte {at} flipped: {err}"
        );
    }
    assert_eq!(refused, 300);
    for len in (0..bytes.len()).step_by(97) {
        assert!(c.state_from_bytes(&bytes[..len]).is_err(), "{len} bytes");
    }
    assert!(c.state_from_bytes(&bytes).is_ok());
}

#[test]
fn a_pose_driven_wall_reaches_each_pose_and_reports_its_mesh() {
    let dir = tempdir("pose");
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/drum_fmu/drum.toml"),
    )
    .unwrap()
    .replace("input = \"velocity\"", "input = \"pose\"");
    std::fs::write(dir.join("drum.toml"), text).unwrap();
    let mut c = Component::instantiate(&dir, "drum.toml").unwrap();
    let orientation = c.variable("drum.orientation").unwrap();
    assert_eq!(
        c.get_real_vector(orientation).unwrap(),
        vec![1.0, 0.0, 0.0, 0.0]
    );
    c.enter_initialization_mode(0.0).unwrap();
    c.exit_initialization_mode().unwrap();
    let start = c.wall_mesh(0).unwrap().vertices;
    // Half a turn about y in 4 steps, a quarter of a turn per step.
    let mut t = 0.0;
    for k in 1..=2 {
        let angle = 0.5 * std::f64::consts::FRAC_PI_2 * k as f64;
        c.set_real_vector(
            orientation,
            &[(angle / 2.0).cos(), 0.0, (angle / 2.0).sin(), 0.0],
        )
        .unwrap();
        c.do_step(t, 0.02).unwrap();
        t += 0.02;
        let now = c.wall_mesh(0).unwrap().vertices;
        let q = nalgebra::UnitQuaternion::from_scaled_axis(Vector3::y() * angle);
        let reference = nalgebra::Point3::new(0.0, 0.015, 0.0);
        for (a, b) in start.iter().zip(&now) {
            let expected = reference + q * (a - reference);
            assert!((expected - b).norm() < 1e-12, "{expected} vs {b}");
        }
    }
    let vertices = vector(&c, "drum.vertices");
    let mesh = c.wall_mesh(0).unwrap();
    let (now, triangles) = (mesh.vertices, mesh.triangles);
    assert_eq!(vertices.len(), 3 * now.len());
    assert_eq!(vertices[3..6], [now[1].x, now[1].y, now[1].z]);
    assert_eq!(vector(&c, "drum.facet_force").len(), 3 * triangles.len());
    c.set_real_vector(orientation, &[0.0; 4]).unwrap();
    assert!(matches!(
        c.do_step(t, 0.02),
        Err(CosimError::BadValue { .. })
    ));
}

fn tempdir(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("talus-cosim-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn the_output_dir_parameter_writes_the_run_files_while_stepping() {
    let dir = tempdir("output");
    let mut c = drum("drum.toml");
    let out = c.variable("output_dir").unwrap();
    let target = dir.join("run");
    c.set_string(
        &[VarRef {
            var: out,
            element: 0,
        }],
        &[target.to_str().unwrap()],
    )
    .unwrap();
    c.enter_initialization_mode(0.0).unwrap();
    c.exit_initialization_mode().unwrap();
    set_spin(&mut c, 3.0);
    c.do_step(0.0, 0.06).unwrap();
    c.terminate().unwrap();
    let walls = std::fs::read_to_string(target.join("walls.csv")).unwrap();
    // Rows every 10 ms (the scene's csv_interval) from 0 to 0.06 s.
    assert_eq!(walls.lines().count(), 1 + 7, "{walls}");
    assert!(walls.starts_with("time,drum_fx"));
    assert!(target.join("particles.pvd").is_file());
    assert!(target.join("walls.pvd").is_file());
}

/// The simulation's whole state as bytes.
fn sim_bytes(c: &Component) -> Vec<u8> {
    let mut w = talus::scene::StateWriter::default();
    c.simulation().unwrap().write_state(0, &mut w);
    w.into_bytes()
}

#[test]
fn a_step_that_diverges_is_rolled_back_to_the_bits_before_it() {
    let mut c = Component::instantiate(
        Path::new(env!("CARGO_MANIFEST_DIR")),
        "tests/scenes/overflowing.toml",
    )
    .unwrap();
    c.enter_initialization_mode(0.0).unwrap();
    c.exit_initialization_mode().unwrap();
    c.do_step(0.0, 0.01).unwrap();
    let floor = |c: &Component| -> Vec<f64> {
        ["floor.force", "floor.force_end", "kinetic_energy", "time"]
            .iter()
            .flat_map(|n| vector(c, n))
            .collect()
    };
    let (before, outputs_before) = (sim_bytes(&c), floor(&c));
    // The beads reach the floor after about 45 ms.
    for _ in 0..2 {
        let err = c.do_step(0.01, 0.1).unwrap_err();
        assert!(matches!(err, CosimError::Diverged(_)), "{err}");
        assert_eq!(c.mode(), Mode::Step);
        assert_eq!(time(&c), 0.01);
        assert!(
            sim_bytes(&c) == before,
            "the state is the one before the step"
        );
        assert_eq!(bits(&floor(&c)), bits(&outputs_before));
    }
    // Shorter steps that stop short of the floor still go on from there.
    c.do_step(0.01, 0.01).unwrap();
    assert_eq!(time(&c), 0.02);
}

#[test]
fn a_start_within_round_off_before_the_clock_never_takes_it_back() {
    let mut c = started("drum.toml");
    c.do_step(0.0, 0.2).unwrap();
    let force = vector(&c, "drum.force");
    assert!(
        force[2].abs() > 0.1,
        "the bed rests on the shell: {force:?}"
    );
    // 1.3e-11 s early (within the 1e-9 tolerance) by 1e-12 s.
    let t = 0.2 - 1.3e-11;
    c.do_step(t, 1e-12).unwrap();
    assert!(time(&c) >= 0.2, "time went back to {}", time(&c));
    // Too short for a sub-step: the forces of the state are reported, not zero.
    let mean = vector(&c, "drum.force");
    assert!(
        (mean[2] - vector(&c, "drum.force_end")[2]).abs() <= 1e-9 * mean[2].abs(),
        "{mean:?}"
    );
    assert!(mean[2].abs() > 0.1, "{mean:?}");
}

#[test]
fn states_keep_to_their_scene_and_leave_the_life_cycle_to_the_master() {
    let mut c = started("drum.toml");
    c.do_step(0.0, 0.01).unwrap();
    let stepping = c.save_state().unwrap();
    // A state of a step restored during initialisation: still initialising.
    let mut init = drum("drum.toml");
    init.enter_initialization_mode(0.0).unwrap();
    init.restore_state(&stepping).unwrap();
    assert_eq!(init.mode(), Mode::Initialisation);
    assert!(init.do_step(0.01, 0.01).is_err());
    init.exit_initialization_mode().unwrap();
    init.do_step(0.01, 0.01).unwrap();
    // The empty drum has the same walls, but is another scene.
    let mut empty = started("empty_drum.toml");
    let err = empty.restore_state(&stepping).unwrap_err();
    assert!(err.to_string().contains("another scene"), "{err}");
    assert_eq!(time(&empty), 0.0);
}

#[test]
fn a_time_step_far_above_the_suggested_one_warns_and_its_blow_up_is_caught() {
    // The case: dt = 5e-3 s through the parameter, 230 times the suggested
    // step of the drum's beads. The bed's energy grows from nothing while every value
    // stays finite; the step that breaks the energy balance is refused and rolled back.
    let mut c = drum("drum.toml");
    assert!(c.warnings().is_empty(), "{:?}", c.warnings());
    let dt = c.variable("dt").unwrap();
    c.set_real_vector(dt, &[5e-3]).unwrap();
    let warnings = c.warnings();
    assert_eq!(warnings.len(), 1);
    assert!(warnings[0].contains("above the suggested"), "{warnings:?}");
    let times: f64 = warnings[0]
        .split("s (")
        .nth(1)
        .and_then(|s| s.split(" times").next())
        .unwrap()
        .parse()
        .unwrap();
    assert!((200.0..260.0).contains(&times), "{}", warnings[0]);
    c.enter_initialization_mode(0.0).unwrap();
    c.exit_initialization_mode().unwrap();
    set_spin(&mut c, 3.0);
    let mut t = 0.0;
    let diverged = loop {
        let before = (time(&c), vector(&c, "kinetic_energy")[0]);
        match c.do_step(t, 0.05) {
            Ok(()) => t += 0.05,
            Err(e) => {
                assert_eq!((time(&c), vector(&c, "kinetic_energy")[0]), before);
                break e;
            }
        }
        assert!(t < 2.0, "no divergence reported in 2 s");
    };
    println!("refused at t = {t}: {diverged}");
    assert!(matches!(diverged, CosimError::Diverged(_)), "{diverged}");
    assert!(
        diverged.to_string().contains("energy balance"),
        "{diverged}"
    );
    // 96 beads of 0.67 g: what the bed held before the refused step is of the order
    // of what the drum can give it, far below the 17 kJ the step would have made.
    let kinetic = vector(&c, "kinetic_energy")[0];
    assert!(kinetic < 0.1, "{kinetic} J");
}

#[test]
fn the_stable_drum_keeps_its_energy_balance_for_a_second() {
    // The same drum at its own step: no step is refused over 20 communication steps.
    let mut c = started("drum.toml");
    set_spin(&mut c, 6.0);
    for k in 0..20 {
        c.do_step(0.05 * k as f64, 0.05).unwrap();
    }
}

#[test]
fn a_step_of_more_than_1e8_dem_steps_is_refused() {
    // dt = 1e-300 s through the parameter: a 10 ms step would take 1e298 DEM steps
    // (the process would hang); it is refused and nothing changes.
    let mut c = drum("drum.toml");
    let dt = c.variable("dt").unwrap();
    c.set_real_vector(dt, &[1e-300]).unwrap();
    c.enter_initialization_mode(0.0).unwrap();
    c.exit_initialization_mode().unwrap();
    let err = c.do_step(0.0, 0.01).unwrap_err();
    assert!(matches!(err, CosimError::BadStep(_)), "{err}");
    assert!(err.to_string().contains("at most 1e8"), "{err}");
    assert_eq!(time(&c), 0.0);
}

#[test]
fn a_state_with_a_bad_step_or_non_finite_values_is_refused_even_with_its_checksum() {
    // Found by fuzzing: bytes whose checksum was made right after changing them. A
    // negative time step made the next do_step loop for ever; a NaN position would
    // poison every step after it.
    let mut c = started("drum.toml");
    c.do_step(0.0, 0.01).unwrap();
    let bytes = c.state_to_bytes(&c.save_state().unwrap());
    let rewritten = |at: usize, value: f64| {
        let mut body = bytes[..bytes.len() - 4].to_vec();
        body[at..at + 8].copy_from_slice(&value.to_le_bytes());
        let crc = talus::checksum::crc32(&body);
        body.extend_from_slice(&crc.to_le_bytes());
        body
    };
    // Layout: magic, fingerprint, time (16), dt (24), ...; the energy account
    // (80..128), the first particle's id (136), body type (144), position (152).
    for (at, value, words) in [
        (24, -1e-4, "time step"),
        (24, 0.0, "time step"),
        (24, f64::NAN, "time step"),
        (16, f64::INFINITY, "time"),
        (96, f64::NAN, "energy account"),
        (152, f64::NAN, "non-finite"),
    ] {
        let err = c.state_from_bytes(&rewritten(at, value)).unwrap_err();
        assert!(err.to_string().contains(words), "{at}: {err}");
    }
    assert!(c.state_from_bytes(&rewritten(24, 2e-5)).is_ok());
}
