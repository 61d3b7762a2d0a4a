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
