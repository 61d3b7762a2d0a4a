//! The command line: the shipped example runs, and bad input gets an error naming the
//! file and the problem.

use std::process::Command;

fn talus(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_talus"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("run talus");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn pellet_pair_example_reports_the_overlap() {
    let (ok, out, err) = talus(&["contact", "examples/pellet_pair/pair.toml"]);
    assert!(ok, "{err}");
    // The generated and the STL pellet are the same solid.
    assert_eq!(
        out.matches("40 vertices, 60 edges, 22 faces").count(),
        2,
        "{out}"
    );
    assert!(
        out.contains("GJK                     intersecting"),
        "{out}"
    );
    let line = out
        .lines()
        .find(|l| l.contains("overlap volume"))
        .expect("overlap line");
    let volume: f64 = line.split_whitespace().nth(2).unwrap().parse().unwrap();
    // The STL pellet lies along y with one long edge 0.2 mm deep in the top cap: the
    // overlap is a wedge of depth h whose faces meet at the 20-gon's interior angle
    // (162°), so its cross-section is h² tan 81°. Its length lies between the chord of
    // the cap's inscribed circle at the wedge's half-width and the pellet length.
    let h: f64 = 0.2e-3;
    let half_width = h * 81f64.to_radians().tan();
    let section = h * half_width;
    let r_in = 2.75e-3 * 9f64.to_radians().cos();
    let chord = 2.0 * (r_in * r_in - half_width * half_width).sqrt();
    assert!(
        volume > section * chord && volume < section * 5.5e-3,
        "{volume}: {} .. {}",
        section * chord,
        section * 5.5e-3
    );
}

#[test]
fn inspect_a_mesh_and_reject_a_bad_one() {
    let (ok, out, _) = talus(&[
        "inspect",
        "examples/pellet_pair/pellet_mm.stl",
        "--scale",
        "1e-3",
    ]);
    assert!(ok);
    assert!(out.contains("22 faces"), "{out}");
    let dir = std::env::temp_dir().join(format!("talus-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let open = dir.join("open.obj");
    std::fs::write(
        &open,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\n",
    )
    .unwrap();
    let (ok, _, err) = talus(&["inspect", open.to_str().unwrap()]);
    assert!(!ok);
    assert!(
        err.contains("open.obj") && err.contains("not closed"),
        "{err}"
    );
    let (ok, out, _) = talus(&["inspect", open.to_str().unwrap(), "--hull"]);
    assert!(ok && out.contains("4 faces"), "{out}");
}

#[test]
fn bad_pair_file_names_file_and_field() {
    let dir = std::env::temp_dir().join(format!("talus-cli-bad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("bad.toml");
    std::fs::write(
        &file,
        "[[body]]\nname = \"a\"\nshape = { kind = \"sphere\", radius = 1.0 }\n\n[[body]]\nname = \"b\"\nshape = { kind = \"prism\", sides = 2, diameter = 1.0, length = 1.0 }\n",
    )
    .unwrap();
    let (ok, _, err) = talus(&["contact", file.to_str().unwrap()]);
    assert!(!ok);
    assert!(err.contains("bad.toml") && err.contains("sides"), "{err}");
    std::fs::write(
        &file,
        "[[body]]\nname = \"a\"\nshape = { kind = \"sphere\", radius = 1.0 }\ncolour = 3\n",
    )
    .unwrap();
    let (ok, _, err) = talus(&["contact", file.to_str().unwrap()]);
    assert!(!ok);
    assert!(
        err.contains("bad.toml") && err.contains("line 4") && err.contains("colour"),
        "{err}"
    );
}

#[test]
fn bench_runs_on_part_of_the_shipped_settled_bed() {
    // The shipped bed: 10 000 dodecahedra (circumradius 5 mm, inradius 3.97 mm) whose
    // centroids lie in the 0.3155 m box at least an inradius from its walls, and on
    // the floor: a bed about 65 mm deep with a rough top (a few pellets up to 91 mm),
    // not the lattice it was poured from (centroids up to 120 mm).
    let text = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("benches/data/settled_dodecahedra.csv"),
    )
    .expect("shipped bed");
    let rows: Vec<Vec<f64>> = text
        .lines()
        .filter(|l| !l.starts_with('#'))
        .skip(1)
        .map(|l| l.split(',').map(|v| v.parse().expect("number")).collect())
        .collect();
    assert_eq!(rows.len(), 10_000);
    let inradius = 0.005 * 0.7947;
    for r in &rows {
        for (k, x) in r[..3].iter().enumerate() {
            let high = if k == 2 { 0.2 } else { 0.3155 };
            assert!(*x > inradius * 0.99 && *x < high - inradius * 0.99, "{r:?}");
        }
    }
    let top = rows.iter().map(|r| r[2]).fold(0.0, f64::max);
    assert!(top < 0.1, "bed top at {top} m");

    // Its lowest 500 particles, measured for a few steps: every row of scene (a)
    // names them, with contacts among them and with the floor.
    let (ok, out, err) = talus(&["bench", "--scale", "0.05", "--steps", "3"]);
    assert!(ok, "{err}");
    let rows: Vec<&str> = out.lines().filter(|l| l.starts_with("(a)")).collect();
    assert_eq!(rows.len(), 2, "{out}");
    for row in rows {
        let fields: Vec<&str> = row.split_whitespace().collect();
        let n = fields.len();
        assert_eq!(fields[n - 7], "500", "{row}");
        let contacts: f64 = fields[n - 5].parse().unwrap();
        assert!(contacts > 500.0, "{row}");
    }

    // One scene on one thread count: one row.
    let (ok, out, err) = talus(&[
        "bench",
        "--scale",
        "0.05",
        "--steps",
        "2",
        "--scene",
        "a",
        "--threads",
        "2",
    ]);
    assert!(ok, "{err}");
    let rows: Vec<&str> = out.lines().filter(|l| l.starts_with('(')).collect();
    assert_eq!(rows.len(), 1, "{out}");
    assert!(rows[0].starts_with("(a)") && rows[0].split_whitespace().nth(5) == Some("2"));
    // Below the row, each stage's share of the timed steps; together the whole step.
    let stages = out
        .lines()
        .find_map(|l| l.trim().strip_prefix("stages: "))
        .unwrap_or_else(|| panic!("no stage line: {out}"));
    let shares: Vec<f64> = stages
        .split(", ")
        .map(|s| s.rsplit(' ').nth(1).unwrap().parse().unwrap())
        .collect();
    assert_eq!(shares.len(), 8, "{stages}");
    assert!(stages.starts_with("integrate") && stages.contains("pair_contacts"));
    assert!((shares.iter().sum::<f64>() - 100.0).abs() < 0.5, "{stages}");
    // A scene that does not exist is named in the error.
    let (ok, _, err) = talus(&["bench", "--scene", "e"]);
    assert!(!ok && err.contains("--scene e"), "{err}");
    // Scene (d): the three variants of the many-shapes lattice, and their ratios.
    let (ok, out, err) = talus(&[
        "bench",
        "--scale",
        "0.01",
        "--steps",
        "2",
        "--scene",
        "d",
        "--threads",
        "1",
    ]);
    assert!(ok, "{err}");
    let rows = out
        .lines()
        .filter(|l| l.starts_with("(d) ") && !l.contains("setup") && !l.contains("thread(s)"));
    assert_eq!(rows.count(), 3, "{out}");
    assert_eq!(out.matches("s per thousand body types").count(), 2, "{out}");
    assert!(out.contains("125 body types of 20 shapes step at"), "{out}");
}

#[test]
fn bad_remote_fmu_options_are_refused_with_the_reason() {
    let out = std::env::temp_dir().join(format!("talus-cli-remote-{}.fmu", std::process::id()));
    let out = out.to_str().unwrap();
    let scene = "examples/drum_fmu/drum.toml";
    for (args, words) in [
        (vec!["--remote", "/"], "--remote: the key is empty"),
        (
            vec!["--remote", "talus/drum", "--timeout", "0"],
            "--remote: timeout 0 s is not a positive number",
        ),
        (
            vec!["--connect", "tcp/127.0.0.1:7447"],
            "the following required arguments were not provided",
        ),
    ] {
        let mut all = vec!["fmu", scene, "-o", out];
        all.extend(args);
        let (ok, _, err) = talus(&all);
        assert!(!ok && err.contains(words), "{all:?}: {err}");
        assert!(!std::path::Path::new(out).exists());
    }
}
