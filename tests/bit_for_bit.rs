//! The shipped examples run as they did when these checksums were taken: `walls.csv`,
//! `series.csv` and the last ParaView frame of `talus run`, and the whole dynamic state
//! (every f64 of every particle, wall and contact history) after the same run in the
//! library, are compared by checksum with a build from before the backend seam.
//!
//! A change that moves any bit of a trajectory fails here. Such a change may be
//! right (a better kernel); then its author re-takes the checksums with
//! `TALUS_PRINT_CHECKSUMS=1 cargo test --test bit_for_bit -- --nocapture` and says
//! in the commit why the bits moved.

use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use std::process::Command;

use talus::scene::{Scene, Simulation, StateWriter};

/// One example shortened to `end_time`: the checksums of walls.csv, series.csv, the
/// last frame and the final state.
struct Case {
    name: &'static str,
    scene: &'static str,
    end_time: f64,
    checksums: [u64; 4],
}

const CASES: [Case; 3] = [
    Case {
        name: "settling_box",
        scene: "examples/settling_box/scene.toml",
        end_time: 0.04,
        checksums: [
            0x9e67ff0815da3557,
            0xd6fa5b7a1076ff8d,
            0x22fa1b300583c2c0,
            0xed9da034cad028d4,
        ],
    },
    Case {
        name: "drum_quasi2d",
        scene: "examples/drum/quasi2d.toml",
        end_time: 0.03,
        checksums: [
            0x17ed34423bde0539,
            0xb65e1ed59af58ef2,
            0xee638a32aac71c74,
            0x5641d5d98cb625ec,
        ],
    },
    Case {
        name: "fixed_bed",
        scene: "examples/fixed_bed/scene.toml",
        end_time: 0.03,
        checksums: [
            0xfc1c6885498302df,
            0xefc9884127a25b85,
            0x660383da9a42c070,
            0x00bfe3c11f16a1a1,
        ],
    },
];

/// FNV-1a, 64 bits: stable across Rust versions and platforms.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ *b as u64).wrapping_mul(0x0100_0000_01b3)
    })
}

/// The example's text with its end time replaced.
fn shortened(case: &Case) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(case.scene);
    let text = std::fs::read_to_string(&path).unwrap();
    let mut replaced = 0;
    let lines: Vec<String> = text
        .lines()
        .map(|line| {
            if line.trim_start().starts_with("end_time") {
                replaced += 1;
                format!("end_time = {}", case.end_time)
            } else {
                line.to_string()
            }
        })
        .collect();
    assert_eq!(replaced, 1, "{}: one end_time line", case.scene);
    lines.join("\n")
}

fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("bit-for-bit-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Checksums of `talus run`'s files.
fn run_files(case: &Case, dir: &Path) -> [u64; 3] {
    let scene = dir.join("scene.toml");
    std::fs::write(&scene, shortened(case)).unwrap();
    let out = dir.join("out");
    let status = Command::new(env!("CARGO_BIN_EXE_talus"))
        .args(["run", "--quiet", "--threads", "2", "--out"])
        .arg(&out)
        .arg(&scene)
        .output()
        .unwrap();
    assert!(
        status.status.success(),
        "{}",
        String::from_utf8_lossy(&status.stderr)
    );
    let mut frames: Vec<PathBuf> = std::fs::read_dir(out.join("frames"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            p.file_name()
                .unwrap()
                .to_string_lossy()
                .starts_with("particles_")
        })
        .collect();
    frames.sort();
    let read = |p: &Path| std::fs::read(p).unwrap();
    [
        fnv1a(&read(&out.join("walls.csv"))),
        fnv1a(&read(&out.join("series.csv"))),
        fnv1a(&read(frames.last().expect("a frame"))),
    ]
}

/// Checksum of the final state of the same run in the library (2 threads).
fn final_state(case: &Case, dir: &Path) -> u64 {
    let scene = Scene::parse(&shortened(case), &dir.join("scene.toml")).unwrap();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    pool.install(|| {
        let mut sim = Simulation::new(&scene);
        let end = sim.end_time;
        let _ = sim.advance_to(end, |sim, _| {
            if sim.is_settled() {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        });
        let mut w = StateWriter::default();
        sim.snapshot().write(0, &mut w);
        fnv1a(&w.into_bytes())
    })
}

#[test]
fn examples_run_as_before() {
    let print = std::env::var_os("TALUS_PRINT_CHECKSUMS").is_some();
    let mut failures = Vec::new();
    for case in &CASES {
        let dir = scratch(case.name);
        let [walls, series, frame] = run_files(case, &dir);
        let state = final_state(case, &dir);
        let found = [walls, series, frame, state];
        if print {
            println!(
                "{}: checksums: [{:#x}, {:#x}, {:#x}, {:#x}]",
                case.name, walls, series, frame, state
            );
        }
        for (what, (f, e)) in ["walls.csv", "series.csv", "last frame", "final state"]
            .iter()
            .zip(found.iter().zip(&case.checksums))
        {
            if f != e {
                failures.push(format!("{}: {what}: {f:#x}, expected {e:#x}", case.name));
            }
        }
    }
    assert!(failures.is_empty(), "bits moved:\n{}", failures.join("\n"));
}
