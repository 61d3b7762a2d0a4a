//! `talus check` and `talus run`: the plan is printed, a run leaves a ParaView series,
//! CSV series and a summary, and an interrupted run still leaves valid outputs.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

mod common;

use common::LID_BOX as SCENE;

fn write_scene(dir: &Path, end: &str) -> PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    let path = dir.join("scene.toml");
    std::fs::write(&path, SCENE.replace("END", end)).unwrap();
    path
}

fn talus() -> Command {
    Command::new(env!("CARGO_BIN_EXE_talus"))
}

fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

#[test]
fn check_prints_the_plan() {
    let dir = scratch("check");
    let scene = write_scene(&dir, "0.01");
    let out = talus().arg("check").arg(&scene).output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(text.contains("valid scene"));
    assert!(text.contains("particles: 27 at start"), "{text}");
    assert!(text.contains("polyhedron–polyhedron"), "{text}");
    assert!(text.contains("wall 'lid': 2 facets"), "{text}");
    assert!(
        text.contains("wall kinematics: advanced every step"),
        "{text}"
    );
    // The errors to expect: the reference impacts at the scene's step.
    assert!(text.contains("expected errors at dt = "), "{text}");
    assert!(
        text.contains("face ") && text.contains(" edge ") && text.contains("energy account"),
        "{text}"
    );
    // A broken scene: non-zero exit, the message names file, line and field.
    std::fs::write(dir.join("bad.toml"), SCENE.replace("END", "-1")).unwrap();
    let out = talus()
        .arg("check")
        .arg(dir.join("bad.toml"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        err.contains("bad.toml:4:") && err.contains("simulation.end_time"),
        "{err}"
    );
}

#[test]
fn run_writes_the_series_and_the_summary() {
    let dir = scratch("run");
    let scene = write_scene(&dir, "0.005");
    let out_dir = dir.join("out");
    let out = talus()
        .args(["run", "--quiet", "--threads", "2", "--out"])
        .arg(&out_dir)
        .arg(&scene)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out_dir.join("summary.json")).unwrap())
            .unwrap();
    assert_eq!(summary["ended_by"], "end_time");
    assert!((summary["time"].as_f64().unwrap() - 0.005).abs() < 1e-12);
    assert_eq!(summary["steps"], 2500);
    assert_eq!(summary["particles"], 27);
    assert_eq!(summary["threads"], 2);
    // The candidate pairs beside the contacts: at most every pair of the 27.
    let candidates = summary["candidate_pairs"].as_u64().unwrap();
    assert!(candidates <= 27 * 26 / 2, "{candidates}");
    // The time of each stage of the step, in step order; the shares add up to one.
    let stages = summary["stages"].as_array().unwrap();
    assert_eq!(stages.len(), 8);
    assert_eq!(stages[7]["stage"], "fluid");
    assert_eq!(stages[0]["stage"], "integrate");
    let share: f64 = stages.iter().map(|s| s["share"].as_f64().unwrap()).sum();
    assert!((share - 1.0).abs() < 1e-9, "{share}");
    assert!(stages.iter().all(|s| s["seconds"].as_f64().unwrap() >= 0.0));
    // The energy account closes to the steps' error, and the reference impacts
    // (face, edge and vertex on each wall material) are listed.
    let energy = &summary["energy"];
    let field = |k: &str| energy[k].as_f64().unwrap();
    let held = field("kinetic") + field("potential") + field("elastic");
    let error = held - field("start") - field("wall_work") - field("fluid_work")
        + field("dissipated")
        - field("host");
    assert!((error - field("error")).abs() <= 1e-12 * field("start").abs().max(1e-9));
    assert!(field("relative_error").abs() < 1e-2, "{energy}");
    let expected = summary["expected"].as_array().unwrap();
    assert!(
        !expected.is_empty() && expected.len() % 3 == 0,
        "{expected:?}"
    );
    assert!(
        expected
            .iter()
            .all(|i| i["restitution_error"].as_f64().unwrap().abs() < 0.1),
        "{expected:?}"
    );
    // Frames at 0, 1, ..., 5 ms and the final one.
    let pvd = std::fs::read_to_string(out_dir.join("particles.pvd")).unwrap();
    let frames = pvd.matches("<DataSet").count();
    assert!((6..=7).contains(&frames), "{frames} frames");
    let vtp = std::fs::read(out_dir.join("frames/particles_000000.vtp")).unwrap();
    let head = String::from_utf8_lossy(&vtp[..600.min(vtp.len())]);
    // 27 dodecahedra of 12 pentagons, 5 points each.
    assert!(
        head.contains("NumberOfPoints=\"1620\"") && head.contains("NumberOfPolys=\"324\""),
        "{head}"
    );
    assert!(head.contains("Name=\"velocity\""));
    assert!(out_dir.join("frames/walls_000000.vtp").exists());
    let walls = std::fs::read_to_string(out_dir.join("walls.csv")).unwrap();
    let header = walls.lines().next().unwrap();
    assert!(
        header.starts_with("time,box_fx,box_fy,box_fz,box_tx,box_ty,box_tz,box_power,lid_fx"),
        "{header}"
    );
    // The particles rest on the box floor under gravity: the mean vertical force on
    // the box approaches their weight (27 × m g) once settled; here, early, it is at
    // least positive downward on average.
    let rows: Vec<Vec<f64>> = walls
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    assert!(rows.len() >= 6);
    assert!(rows.iter().all(|r| r.iter().all(|x| x.is_finite())));
}

#[test]
fn an_interrupted_run_leaves_valid_outputs() {
    let dir = scratch("interrupt");
    let scene = write_scene(&dir, "100.0");
    let out_dir = dir.join("out");
    let child = talus()
        .args(["run", "--quiet", "--out"])
        .arg(&out_dir)
        .arg(&scene)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Wait for the first frame, then interrupt.
    let start = Instant::now();
    while !out_dir.join("particles.pvd").exists() {
        assert!(start.elapsed() < Duration::from_secs(60));
        std::thread::sleep(Duration::from_millis(50));
    }
    std::thread::sleep(Duration::from_millis(500));
    let status = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let out = child.wait_with_output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out_dir.join("summary.json")).unwrap())
            .unwrap();
    assert_eq!(summary["ended_by"], "interrupted");
    assert!(summary["time"].as_f64().unwrap() < 100.0);
    let pvd = std::fs::read_to_string(out_dir.join("particles.pvd")).unwrap();
    assert!(pvd.trim_end().ends_with("</VTKFile>"));
}

#[test]
fn a_run_that_blows_up_stops_with_the_step_and_finite_outputs() {
    // The settling box at 50 times its suggested step: the dodecahedra gain hundreds
    // of joules from nothing and leave the box; the run stops at the first energy
    // check that sees it, names the step, and no row or frame after it is written.
    let dir = scratch("blow_up");
    std::fs::create_dir_all(&dir).unwrap();
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/settling_box/scene.toml"),
    )
    .unwrap()
    .replace("dt = \"auto\"", "dt = 3.827e-4");
    let scene = dir.join("scene.toml");
    std::fs::write(&scene, text).unwrap();
    let out_dir = dir.join("out");
    let out = talus()
        .args(["run", "--quiet", "--out"])
        .arg(&out_dir)
        .arg(&scene)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{err}");
    assert!(
        err.contains("the run diverged") && err.contains("energy balance"),
        "{err}"
    );
    assert!(
        err.contains("the time step 3.827e-4 s is too long"),
        "{err}"
    );
    let step: u64 = err
        .split("up to step ")
        .nth(1)
        .and_then(|s| s.split(' ').next())
        .unwrap()
        .parse()
        .unwrap();
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out_dir.join("summary.json")).unwrap())
            .unwrap();
    assert_eq!(summary["ended_by"], "diverged");
    assert_eq!(summary["steps"].as_u64().unwrap(), step);
    // Every row before is finite, and the last row is before the step.
    let series = std::fs::read_to_string(out_dir.join("series.csv")).unwrap();
    let rows: Vec<Vec<f64>> = series
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    assert!(rows.iter().flatten().all(|x| x.is_finite()));
    let t_step = summary["time"].as_f64().unwrap();
    assert!(rows.last().unwrap()[0] < t_step);
}
