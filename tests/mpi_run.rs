//! `mpirun -np N talus run` (feature `mpi`): the ranks split the scene and write one
//! output set, the one a single process writes (a box poured from an inlet; a bed
//! fed from a box riding above it, its buried particles frozen, and its packing
//! analysed; the quasi-2D drum turning, with its analysis; a column of particles
//! in a coupled gas flow); checkpoints written by N ranks resume on M ranks or in
//! one process; a SIGTERM to mpirun ends every rank with the outputs written.
//!
//! Particles move to the bits of one process, so the frames (positions,
//! orientations, velocities) and `series.csv` (counts, kinetic energy, largest
//! speed: sums of the same bits in the same order on rank 0's gathered world) are
//! the same bytes. Wall forces are summed over ranks in another grouping than one
//! process's sum over particles: they agree to round-off, about 1e-15 relative,
//! which may change the tenth significant digit the CSV prints.
#![cfg(feature = "mpi")]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

/// The settling box of the examples, poured from its inlet for `end_time`.
fn settling_box(dir: &Path, end_time: f64) -> PathBuf {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/settling_box/scene.toml");
    let text = std::fs::read_to_string(path).expect("the example is shipped");
    let text = text.replace("end_time = 0.6", &format!("end_time = {end_time}"));
    std::fs::create_dir_all(dir).unwrap();
    let scene = dir.join("box.toml");
    std::fs::write(&scene, text).unwrap();
    scene
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("talus-mpi-run-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// `talus` with `args` under `mpirun -np ranks` (more ranks than cores allowed; as
/// root with OpenMPI's consent variables).
fn mpirun(ranks: usize, args: &[&str]) -> Command {
    let mut c = Command::new("mpirun");
    c.args(["--oversubscribe", "-np", &ranks.to_string()])
        .arg(env!("CARGO_BIN_EXE_talus"))
        .args(args)
        .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1");
    c
}

fn text(out: &Output) -> String {
    format!(
        "{}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    )
}

fn read(path: &Path) -> Vec<u8> {
    std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn summary(dir: &Path) -> serde_json::Value {
    serde_json::from_slice(&read(&dir.join("summary.json"))).unwrap()
}

/// Runs `scene` in one process into `dir/one` and on `ranks` ranks into
/// `dir/ranks` (one thread each); returns the two directories.
fn run_both(scene: &Path, dir: &Path, ranks: usize) -> (PathBuf, PathBuf) {
    let scene = scene.to_str().unwrap();
    let (one, many) = (dir.join("one"), dir.join("ranks"));
    let out = Command::new(env!("CARGO_BIN_EXE_talus"))
        .args(["run", scene, "--quiet", "--threads", "1", "--out"])
        .arg(&one)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", text(&out));
    let out = mpirun(ranks, &["run", scene, "--quiet", "--threads", "1", "--out"])
        .arg(&many)
        .output()
        .expect("mpirun (openmpi-bin, scripts/system-deps.sh)");
    assert!(out.status.success(), "{}", text(&out));
    // One summary line, from rank 0.
    let said = String::from_utf8_lossy(&out.stdout);
    assert_eq!(said.matches("finished at").count(), 1, "{said}");
    (one, many)
}

/// The frames (at least `frames` of particles and walls) and `files` of both
/// directories are the same bytes.
fn assert_same_bytes(one: &Path, many: &Path, frames: usize, files: &[&str]) {
    let listed = |d: &Path| -> Vec<_> {
        let mut names: Vec<_> = std::fs::read_dir(d.join("frames"))
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        names.sort();
        names
    };
    let names = listed(one);
    assert_eq!(names, listed(many));
    assert!(names.len() >= 2 * frames, "{names:?}");
    for f in &names {
        let (a, b) = (
            read(&one.join("frames").join(f)),
            read(&many.join("frames").join(f)),
        );
        assert!(a == b, "{f:?} differs between one process and the ranks");
    }
    for f in files {
        assert!(read(&one.join(f)) == read(&many.join(f)), "{f} differs");
    }
}

/// `file` (a CSV of numbers) of both directories: the same rows, each number
/// within 1e-9 of its column's largest (the walls' forces are summed over ranks in
/// another grouping than one process's sum over particles: they agree to
/// round-off, which may change the tenth digit printed). Returns the rows.
fn assert_close_columns(one: &Path, many: &Path, file: &str) -> usize {
    let table = |d: &Path| -> Vec<Vec<f64>> {
        String::from_utf8(read(&d.join(file)))
            .unwrap()
            .lines()
            .skip(1)
            .map(|l| {
                l.split(',')
                    .map(|x| x.parse().unwrap_or(f64::NAN))
                    .collect()
            })
            .collect()
    };
    let (a, b) = (table(one), table(many));
    assert_eq!(a.len(), b.len(), "{file}");
    for col in 0..a[0].len() {
        let largest = a.iter().map(|r| r[col].abs()).fold(0.0, f64::max);
        for (ra, rb) in a.iter().zip(&b) {
            let same = (ra[col].is_nan() && rb[col].is_nan())
                || (ra[col] - rb[col]).abs() <= 1e-9 * largest;
            assert!(
                same,
                "{file} column {col} at t = {}: {} against {}",
                ra[0], ra[col], rb[col]
            );
        }
    }
    a.len()
}

#[test]
fn talus_run_on_three_ranks_writes_what_one_process_writes() {
    let dir = scratch("three");
    let scene = settling_box(&dir, 0.1);
    let (one, three) = run_both(&scene, &dir, 3);
    // 0.1 s at 0.02 s a frame: six frames.
    assert_same_bytes(
        &one,
        &three,
        6,
        &["particles.pvd", "walls.pvd", "series.csv"],
    );

    let rows = assert_close_columns(&one, &three, "walls.csv");
    assert!(rows >= 50, "a row every 2 ms: {rows}");

    let (s1, s3) = (summary(&one), summary(&three));
    for key in [
        "ended_by",
        "steps",
        "particles",
        "frozen",
        "contacts",
        "candidate_pairs",
        "frames",
    ] {
        assert_eq!(s1[key], s3[key], "summary.json {key}");
    }
    assert_eq!(s1["particles"], 200);
    let close = |key: &str, part: Option<&str>| {
        let (x, y) = match part {
            Some(p) => (&s1[key][p], &s3[key][p]),
            None => (&s1[key], &s3[key]),
        };
        let (x, y) = (x.as_f64().unwrap(), y.as_f64().unwrap());
        assert!(
            (x - y).abs() <= 1e-12 * x.abs().max(y.abs()),
            "summary.json {key} {part:?}: {x} against {y}"
        );
    };
    close("kinetic_energy", None);
    close("max_speed", None);
    for part in ["dissipated", "wall_work", "kinetic", "elastic"] {
        close("energy", Some(part));
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn sigterm_to_mpirun_ends_every_rank_with_the_outputs_written() {
    let dir = scratch("sigterm");
    let scene = settling_box(&dir, 60.0);
    let out = dir.join("out");
    let mut child = mpirun(2, &["run", scene.to_str().unwrap(), "--quiet", "--out"])
        .arg(&out)
        .spawn()
        .unwrap();
    // Until the run has written a few rows of its minute.
    let started = Instant::now();
    let rows = || std::fs::read_to_string(out.join("series.csv")).map_or(0, |t| t.lines().count());
    while rows() < 5 {
        assert!(
            started.elapsed() < Duration::from_secs(60),
            "no rows written"
        );
        std::thread::sleep(Duration::from_millis(50));
    }
    let term = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(term.success());
    let waited = Instant::now();
    loop {
        if child.try_wait().unwrap().is_some() {
            break;
        }
        assert!(
            waited.elapsed() < Duration::from_secs(30),
            "the ranks did not end"
        );
        std::thread::sleep(Duration::from_millis(50));
    }
    let s = summary(&out);
    assert_eq!(s["ended_by"], "interrupted");
    let t = s["time"].as_f64().unwrap();
    assert!(t > 0.0 && t < 60.0, "ended at {t}");
    // The last row is at the end, as an uninterrupted run's last row is.
    let last = std::fs::read_to_string(out.join("series.csv")).unwrap();
    let last_t: f64 = last
        .lines()
        .last()
        .and_then(|l| l.split(',').next())
        .and_then(|x| x.parse().ok())
        .unwrap();
    assert!(
        (last_t - t).abs() <= 1e-9 * t,
        "last row at {last_t}, end at {t}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The settling box poured for 0.1 s with a checkpoint every 35 ms, on two ranks:
/// the newest checkpoint (at 70 ms, the whole run's state gathered on rank 0)
/// resumes on three ranks and in one process, one process's resumes on two ranks,
/// and each resumed run ends with the frames and series of an uninterrupted
/// one-process run, byte for byte.
#[test]
fn checkpoints_resume_on_any_number_of_ranks() {
    let dir = scratch("resume");
    let scene = settling_box(&dir, 0.1);
    let with_checkpoints = std::fs::read_to_string(&scene).unwrap().replace(
        "csv_interval = 0.002",
        "csv_interval = 0.002\ncheckpoint_interval = 0.035",
    );
    std::fs::write(&scene, with_checkpoints).unwrap();
    let (one, two) = run_both(&scene, &dir, 2);
    assert!(two.join("checkpoint.talus").exists());
    let copy = |from: &Path, name: &str| {
        let to = dir.join(name);
        let status = Command::new("cp").arg("-r").arg(from).arg(&to).status();
        assert!(status.unwrap().success());
        to
    };
    let (two_in_one, one_on_two) = (copy(&two, "two_in_one"), copy(&one, "one_on_two"));

    let resume = |dir: &Path| {
        vec![
            "run".to_string(),
            "--resume".into(),
            dir.display().to_string(),
            "--quiet".into(),
            "--threads".into(),
            "1".into(),
        ]
    };
    let args = resume(&two);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let out = mpirun(3, &args).output().unwrap();
    assert!(out.status.success(), "{}", text(&out));
    let said = String::from_utf8_lossy(&out.stdout);
    assert!(said.contains("finished at t = 1.000000e-1 s"), "{said}");
    let out = Command::new(env!("CARGO_BIN_EXE_talus"))
        .args(resume(&two_in_one))
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", text(&out));
    let args = resume(&one_on_two);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let out = mpirun(2, &args).output().unwrap();
    assert!(out.status.success(), "{}", text(&out));
    for resumed in [&two, &two_in_one, &one_on_two] {
        assert_same_bytes(&one, resumed, 6, &["particles.pvd", "series.csv"]);
        assert_eq!(summary(resumed)["steps"], summary(&one)["steps"]);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The fluid column of the face tests (spheres and dodecahedra in a gas flow,
/// shares every 5 steps) for 50 ms on three ranks: the particles', the
/// fluid's frames (solid fraction, mean particle velocity, each cell's drag) and
/// series.csv are one process's bytes; the work of the fluid's forces agrees to
/// round-off.
#[test]
fn a_coupled_fluid_runs_on_three_ranks_as_in_one_process() {
    let dir = scratch("fluid");
    std::fs::create_dir_all(&dir).unwrap();
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/scenes/fluid_column.toml");
    let text = std::fs::read_to_string(path)
        .unwrap()
        .replace("end_time = 1.0", "end_time = 0.05")
        // A side wind pushes the particles across the ranks' boundaries between
        // two updates of the shares: they must take their rows with them.
        .replace("velocity = [0.0, 0.0, 2.0]", "velocity = [3.0, 1.0, 2.0]")
        .replace(
            "[simulation]",
            "[output]\nframe_interval = 0.005\ncsv_interval = 0.001\n\n[simulation]",
        );
    let scene = dir.join("column.toml");
    std::fs::write(&scene, text).unwrap();
    let (one, three) = run_both(&scene, &dir, 3);
    assert_same_bytes(
        &one,
        &three,
        10,
        &["particles.pvd", "fluid.pvd", "series.csv"],
    );
    let fluid_frames = std::fs::read_dir(three.join("frames"))
        .unwrap()
        .filter(|e| {
            e.as_ref()
                .unwrap()
                .file_name()
                .to_string_lossy()
                .starts_with("fluid_")
        })
        .count();
    assert!(fluid_frames >= 10, "{fluid_frames} fluid frames");
    let (s1, s3) = (summary(&one), summary(&three));
    assert_eq!(s1["steps"], s3["steps"]);
    let work = |s: &serde_json::Value| s["energy"]["fluid_work"].as_f64().unwrap();
    assert!(work(&s1) != 0.0);
    assert!((work(&s1) - work(&s3)).abs() <= 1e-12 * work(&s1).abs());
    let _ = std::fs::remove_dir_all(&dir);
}

/// A bed of spheres (d = 5 mm) in a tube of 2 cm, fed at 400 per second from a box
/// riding 2–5 cm above the bed height (measured every 5 ms), the spheres more than
/// 2 cm below it frozen: on two ranks, rank 0 measures the bed from the top layers
/// of both, every rank moves the box and freezes its own buried spheres, and the
/// outputs, the packing analysis included, are one process's.
#[test]
fn a_bed_fed_from_above_and_frozen_packs_alike_on_two_ranks() {
    let dir = scratch("bed");
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("bed.toml");
    std::fs::write(&scene, BED).unwrap();
    let (one, two) = run_both(&scene, &dir, 2);
    // 0.6 s at 0.1 s a frame: seven frames.
    let files = [
        "series.csv",
        "packing.json",
        "poses.csv",
        "packing_axial.csv",
    ];
    assert_same_bytes(&one, &two, 7, &files);
    let s = summary(&two);
    // 0.6 s at 400 per second from the first at t = 0: 241 due at the end; a
    // particle that finds no free place waits for the next step, so the last may
    // not be in yet (one of the two, depending on where the bed left room).
    let particles = s["particles"].as_u64().unwrap();
    assert!(
        (240..=241).contains(&particles),
        "{particles} particles: 0.6 s at 400 per second"
    );
    assert!(s["frozen"].as_u64().unwrap() > 100, "{}", s["frozen"]);
    assert_eq!(s["frozen"], summary(&one)["frozen"]);
    let _ = std::fs::remove_dir_all(&dir);
}

const BED: &str = r#"
[simulation]
dt = "auto"
end_time = 0.6
gravity = [0.0, 0.0, -9.81]
seed = 4

[output]
frame_interval = 0.1
csv_interval = 0.005

[materials.glass]
density = 2500.0
young = 1e6
poisson = 0.25
restitution = 0.3
friction = 0.3

[shapes.ball]
kind = "sphere"
radius = 0.0025

[[wall]]
name = "tube"
material = "glass"
geometry = { kind = "cylinder", base = [0.0, 0.0, 0.0], axis = [0.0, 0.0, 1.0], length = 0.3, radius = 0.01, sides = 64, bottom = true }

[[inlet]]
shape = "ball"
material = "glass"
min = [-0.0065, -0.0065, 0.02]
max = [0.0065, 0.0065, 0.05]
rate = 400.0
count = 2000
bed_height = 0.15
above_bed = true

[bed]
base = [0.0, 0.0, 0.0]
radius = 0.01
exclude = 0.005
freeze = { depth = 0.02, max_speed = 0.01 }
"#;

/// The quasi-2D drum of the examples turning at 45 rpm for 0.1 s on two ranks:
/// the frames and `series.csv` are one process's bytes, the drum's rows (drive
/// torque, power, the bed's gravity moment from the mass moments summed over the
/// ranks, the angle of repose fitted to the whole bed gathered at each sample)
/// agree to round-off, and its velocity field is one process's.
#[test]
fn the_drum_turns_and_is_analysed_alike_on_two_ranks() {
    let dir = scratch("drum");
    std::fs::create_dir_all(&dir).unwrap();
    let example = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/drum/quasi2d.toml");
    let text = std::fs::read_to_string(example).unwrap();
    let short = text.replace("end_time = 4.0 ", "end_time = 0.1 #");
    assert_ne!(short, text);
    let scene = dir.join("drum.toml");
    std::fs::write(&scene, short).unwrap();
    let (one, two) = run_both(&scene, &dir, 2);
    assert_same_bytes(&one, &two, 5, &["series.csv", "drum_field.csv"]);
    let rows = assert_close_columns(&one, &two, "drum.csv");
    assert!(rows >= 10, "a row every 10 ms: {rows}");
    assert_close_columns(&one, &two, "walls.csv");
    let _ = std::fs::remove_dir_all(&dir);
}
