//! `talus run` checkpoints and `--resume`: a run killed with SIGKILL at random points,
//! in the middle of writing a checkpoint and between its two renames, and resumed each
//! time, leaves the same outputs, bit for bit, as a run never stopped; checkpoints
//! that are damaged, truncated, of another scene or no checkpoint at all are refused.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant, SystemTime};

use rand::{Rng, SeedableRng};

mod common;

/// The lid pressed into 27 dodecahedra, with a checkpoint every 4 ms.
fn scene_text() -> String {
    common::LID_BOX.replace(
        "frame_interval = 0.001",
        "frame_interval = 0.001\ncheckpoint_interval = 0.004",
    )
}

fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn write_scene(dir: &Path, end: &str) -> PathBuf {
    let path = dir.join("scene.toml");
    std::fs::write(&path, scene_text().replace("END", end)).unwrap();
    path
}

fn talus(args: &[&Path]) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_talus"));
    c.args(args).arg("--quiet").arg("--threads").arg("2");
    c
}

fn finished(out: Output) -> String {
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(out.status.success(), "{err}");
    err
}

fn resume(dir: &Path) -> Command {
    talus(&[Path::new("run"), Path::new("--resume"), dir])
}

fn rows(dir: &Path) -> usize {
    std::fs::read_to_string(dir.join("series.csv")).map_or(0, |s| s.lines().count())
}

/// Starts `command` and kills it (SIGKILL) once `ready` holds; fails if the run ends
/// first.
fn kill_when(mut command: Command, ready: impl Fn() -> bool) {
    let mut child: Child = command.stdout(Stdio::null()).spawn().unwrap();
    let started = Instant::now();
    loop {
        if ready() {
            child.kill().unwrap();
            let status = child.wait().unwrap();
            assert!(!status.success(), "killed, not finished");
            return;
        }
        if let Some(status) = child.try_wait().unwrap() {
            panic!("the run ended ({status}) before the kill point");
        }
        assert!(
            started.elapsed() < Duration::from_secs(120),
            "no kill point"
        );
        std::thread::sleep(Duration::from_millis(2));
    }
}

/// Every output file of a run, by name relative to `dir`, with the summary's
/// wall-clock fields left out, and its count of candidate pairs: that is what the
/// neighbour list holds, which depends on where the list was last built, and a
/// resumed run builds its list afresh where it resumes (the contacts, forces and
/// every other figure do not depend on it).
fn outputs(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut files = Vec::new();
    for sub in ["", "frames"] {
        let mut names: Vec<_> = std::fs::read_dir(dir.join(sub))
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.is_file() && !p.to_string_lossy().contains("checkpoint"))
            .collect();
        names.sort();
        for p in names {
            let name = p.strip_prefix(dir).unwrap().display().to_string();
            let mut bytes = std::fs::read(&p).unwrap();
            if name == "summary.json" {
                let mut v: serde_json::Value = serde_json::from_slice(&bytes).unwrap();
                let m = v.as_object_mut().unwrap();
                for k in [
                    "wall_clock_s",
                    "particle_steps_per_s",
                    "contacts_per_s",
                    "stages",
                    "candidate_pairs",
                ] {
                    assert!(m.remove(k).is_some(), "{k}");
                }
                bytes = serde_json::to_vec_pretty(&v).unwrap();
            }
            files.push((name, bytes));
        }
    }
    files
}

fn assert_same_outputs(a: &Path, b: &Path) {
    let (a, b) = (outputs(a), outputs(b));
    let names = |f: &[(String, Vec<u8>)]| f.iter().map(|x| x.0.clone()).collect::<Vec<_>>();
    assert_eq!(names(&a), names(&b));
    assert!(a.len() > 20, "{} files", a.len());
    for ((name, x), (_, y)) in a.iter().zip(&b) {
        // A text file's lines that differ, so that a failure says what changed.
        let differing = || {
            let (x, y) = (String::from_utf8_lossy(x), String::from_utf8_lossy(y));
            let lines: Vec<_> = x
                .lines()
                .zip(y.lines())
                .filter(|(a, b)| a != b)
                .take(3)
                .collect();
            format!("{lines:?}")
        };
        assert!(x == y, "{name} differs after resuming: {}", differing());
    }
}

#[test]
fn a_run_killed_anywhere_and_resumed_gives_the_same_outputs() {
    let dir = scratch("resume_killed");
    let scene = write_scene(&dir, "0.1");
    let (whole, killed) = (dir.join("whole"), dir.join("killed"));
    let run = talus(&[Path::new("run"), &scene, Path::new("--out"), &whole])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&run.stdout).to_string();
    finished(run);
    assert_eq!(rows(&whole), 102, "a header, t = 0 and 100 rows");
    // Below the summary, the last step's contacts, between particles among the
    // candidate pairs and with walls (those of summary.json), and each stage's share
    // of the run, adding up to the whole.
    let line = stdout
        .lines()
        .find_map(|l| l.trim().strip_prefix("last step: "))
        .unwrap_or_else(|| panic!("no last-step line: {stdout}"));
    let (counts, stages) = line.split_once("; stages: ").expect(line);
    let words: Vec<&str> = counts.split_whitespace().collect();
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(whole.join("summary.json")).unwrap())
            .unwrap();
    assert_eq!(words[0], summary["contacts"].to_string(), "{line}");
    assert_eq!(words[2], summary["pair_contacts"].to_string(), "{line}");
    assert_eq!(words[6], summary["candidate_pairs"].to_string(), "{line}");
    let number = |k: usize| -> usize { words[k].parse().unwrap() };
    let (contacts, pairs, candidates, walls) = (number(0), number(2), number(6), number(10));
    assert!(pairs > 0 && candidates >= pairs, "{line}");
    assert_eq!(pairs + walls, contacts, "{line}");
    let shares: Vec<f64> = stages
        .split(", ")
        .map(|s| s.rsplit(' ').nth(1).unwrap().parse().unwrap())
        .collect();
    assert_eq!(shares.len(), 8, "{stages}");
    assert!((shares.iter().sum::<f64>() - 100.0).abs() < 0.5, "{stages}");

    let seed = SystemTime::now()
        .duration_since(SystemTime::UNIX_EPOCH)
        .unwrap()
        .as_nanos() as u64;
    println!("kill points from seed {seed}");
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    // Two kills at random rows, resumed each time.
    let first = rng.random_range(8..30);
    kill_when(
        talus(&[Path::new("run"), &scene, Path::new("--out"), &killed]),
        || rows(&killed) >= first,
    );
    let second = rng.random_range(first + 8..first + 30);
    kill_when(resume(&killed), || rows(&killed) >= second);

    // In the middle of writing the temporary file.
    let temp = killed.join("checkpoint.talus.tmp");
    let newest = killed.join("checkpoint.talus");
    let mut pausing = resume(&killed);
    pausing.env("TALUS_TEST_CHECKPOINT_PAUSE_MS", "150");
    kill_when(pausing, || temp.exists());
    // Between renaming the newest to the previous one and the new one into place:
    // only the previous checkpoint is whole.
    let mut pausing = resume(&killed);
    pausing.env("TALUS_TEST_CHECKPOINT_PAUSE_MS", "150");
    kill_when(pausing, || temp.exists() && !newest.exists());
    assert!(!newest.exists());

    let err = finished(resume(&killed).output().unwrap());
    assert!(!err.contains("passed over"), "{err}");
    assert_same_outputs(&whole, &killed);
}

#[test]
fn damaged_foreign_and_missing_checkpoints_are_refused() {
    let dir = scratch("resume_refused");
    let scene = write_scene(&dir, "0.012");
    let (whole, run) = (dir.join("whole"), dir.join("run"));
    for out in [&whole, &run] {
        finished(
            talus(&[Path::new("run"), &scene, Path::new("--out"), out])
                .output()
                .unwrap(),
        );
    }
    let newest = run.join("checkpoint.talus");
    let previous = run.join("checkpoint.prev.talus");
    let good = std::fs::read(&newest).unwrap();
    let good_previous = std::fs::read(&previous).unwrap();

    // A truncated newest checkpoint: the previous one is taken, with a warning, and
    // the run ends as the whole one did.
    std::fs::write(&newest, &good[..good.len() / 2]).unwrap();
    let err = finished(resume(&run).output().unwrap());
    assert!(
        err.contains("passed over") && err.contains("checkpoint.talus: damaged state"),
        "{err}"
    );
    assert_same_outputs(&whole, &run);

    let refused = |what: &str| {
        let out = resume(&run).output().unwrap();
        assert!(!out.status.success(), "{what} accepted");
        String::from_utf8_lossy(&out.stderr).to_string()
    };
    // One flipped byte in each.
    let mut flipped = good.clone();
    flipped[good.len() / 3] ^= 0x10;
    std::fs::write(&newest, &flipped).unwrap();
    let mut flipped = good_previous.clone();
    flipped[40] ^= 0x01;
    std::fs::write(&previous, &flipped).unwrap();
    let err = refused("flipped bytes");
    assert!(
        err.contains("no usable checkpoint") && err.matches("damaged state").count() == 2,
        "{err}"
    );
    // Not a checkpoint, and one of another format version.
    std::fs::write(&newest, b"hello").unwrap();
    let mut other_version = good.clone();
    other_version[7] = b'9';
    std::fs::write(&previous, &other_version).unwrap();
    let err = refused("not a checkpoint");
    assert_eq!(
        err.matches("not a checkpoint of this talus version")
            .count(),
        2,
        "{err}"
    );
    // Another scene: the scene file changed since.
    std::fs::write(&newest, &good).unwrap();
    std::fs::remove_file(&previous).unwrap();
    std::fs::write(&scene, scene_text().replace("END", "0.02")).unwrap();
    let err = refused("another scene");
    assert!(err.contains("another scene"), "{err}");
    // A scene given with --resume must be the checkpoint's.
    let other = dir.join("other.toml");
    std::fs::write(&other, scene_text().replace("END", "0.03")).unwrap();
    let out = talus(&[Path::new("run"), &other, Path::new("--resume"), &run])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("another scene"));
    // Nothing to resume.
    let empty = dir.join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    let out = resume(&empty).output().unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("no checkpoint to resume from"), "{err}");
}

#[test]
fn a_drum_interrupted_and_resumed_gives_the_same_outputs() {
    // The drum's monitor (torque sums, revolutions, the velocity field) travels in the
    // checkpoint that an interrupted run (Ctrl-C, a scheduler's SIGTERM) writes.
    let dir = scratch("resume_drum");
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/drum/quasi2d.toml"),
    )
    .unwrap();
    let text: String = text
        .lines()
        .map(|l| match l.trim_start().starts_with("end_time") {
            true => "end_time = 0.08\n".to_string(),
            false => format!("{l}\n"),
        })
        .collect();
    let scene = dir.join("drum.toml");
    std::fs::write(&scene, text).unwrap();
    let (whole, stopped) = (dir.join("whole"), dir.join("stopped"));
    finished(
        talus(&[Path::new("run"), &scene, Path::new("--out"), &whole])
            .output()
            .unwrap(),
    );
    let child = talus(&[Path::new("run"), &scene, Path::new("--out"), &stopped])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let started = Instant::now();
    while rows(&stopped) < 4 {
        assert!(started.elapsed() < Duration::from_secs(60));
        std::thread::sleep(Duration::from_millis(2));
    }
    let signal = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(signal.success());
    let err = finished(child.wait_with_output().unwrap());
    assert!(err.contains("continue with: talus run --resume"), "{err}");
    let summary = std::fs::read_to_string(stopped.join("summary.json")).unwrap();
    assert!(summary.contains("\"interrupted\""), "{summary}");

    finished(resume(&stopped).output().unwrap());
    assert!(stopped.join("drum_field.png").exists());
    assert_same_outputs(&whole, &stopped);
}

#[test]
fn checkpoints_by_wall_clock_time() {
    let dir = scratch("resume_wall_clock");
    let scene = dir.join("scene.toml");
    std::fs::write(&scene, common::LID_BOX.replace("END", "0.01")).unwrap();
    let out = dir.join("out");
    let every = |minutes: &str| {
        talus(&[Path::new("run"), &scene, Path::new("--out"), &out])
            .arg(format!("--checkpoint-every={minutes}"))
            .output()
            .unwrap()
    };
    for bad in ["0", "-1", "nan", "soon"] {
        let o = every(bad);
        assert!(!o.status.success(), "{bad}");
        assert!(
            String::from_utf8_lossy(&o.stderr).contains("not a positive number of minutes"),
            "{bad}"
        );
    }
    // Every 6 ms of wall-clock: several checkpoints in a run of about a second.
    finished(every("0.0001"));
    assert!(out.join("checkpoint.talus").exists());
    assert!(out.join("checkpoint.prev.talus").exists());
    let whole = dir.join("whole");
    std::fs::rename(&out, &whole).unwrap();
    finished(every("0.0001"));
    std::fs::remove_file(out.join("checkpoint.talus")).unwrap();
    finished(resume(&out).output().unwrap());
    assert_same_outputs(&whole, &out);
}
