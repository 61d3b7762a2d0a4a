//! The native C API: the header is cbindgen's and matches the exported functions,
//! and a C program compiled against it drives a drum scene (results, misuse,
//! rollback).

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::Command;

mod common;

/// The generator of the header (its `main` writes the file).
#[allow(dead_code)]
#[path = "../examples/c_header.rs"]
mod c_header;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn the_header_is_what_cbindgen_generates() {
    let mut generated = Vec::new();
    c_header::c_header(root()).write(&mut generated);
    let committed = std::fs::read(root().join("interfaces/c/talus.h")).unwrap();
    assert!(
        generated == committed,
        "interfaces/c/talus.h differs from what cbindgen generates from src/ffi/mod.rs: \
         run `cargo run --example c_header` and commit the header"
    );
    // The doc comments came over.
    let text = String::from_utf8(generated).unwrap();
    assert!(
        text.contains("// Advances from `t` (the current time) by `h`."),
        "{text}"
    );
}

/// Names `talus_*` followed by `(` in a text.
fn functions(text: &str, prefix: &str) -> BTreeSet<String> {
    text.match_indices(prefix)
        .filter_map(|(i, _)| {
            let rest = &text[i..];
            let end = rest.find(|c: char| !(c.is_alphanumeric() || c == '_'))?;
            rest[end..]
                .starts_with('(')
                .then(|| rest[..end].to_string())
        })
        .collect()
}

#[test]
fn the_header_declares_exactly_the_exported_functions() {
    let header = std::fs::read_to_string(root().join("interfaces/c/talus.h")).unwrap();
    // Declarations only: drop the usage example in the leading comment.
    let declarations = &header[header.find("#ifndef TALUS_H").unwrap()..];
    let rust = std::fs::read_to_string(root().join("src/ffi/mod.rs")).unwrap();
    let exported: BTreeSet<String> = rust
        .split("#[unsafe(no_mangle)]")
        .skip(1)
        .flat_map(|item| {
            functions(item.split('{').next().unwrap(), "talus_")
                .into_iter()
                .take(1)
        })
        .collect();
    assert_eq!(functions(declarations, "talus_"), exported);
    assert!(exported.len() >= 20, "{exported:?}");
}

/// The directory with libtalus.so: the one holding the test's `talus` binary.
fn library_dir() -> PathBuf {
    Path::new(env!("CARGO_BIN_EXE_talus"))
        .parent()
        .unwrap()
        .to_path_buf()
}

/// Compiles `tests/c/{program}.c` against the header and libtalus.so, runs it on
/// `scene` and returns what it printed, after checking it exited 0 with "ok".
fn run_c_program(program: &str, scene: &str) -> String {
    let lib = library_dir();
    assert!(
        lib.join("libtalus.so").exists(),
        "no libtalus.so in {}",
        lib.display()
    );
    let out = std::env::temp_dir().join(format!("talus-{program}-{}", std::process::id()));
    let status = Command::new("cc")
        .args(["-std=c99", "-Wall", "-Wextra", "-Werror", "-o"])
        .arg(&out)
        .arg(root().join(format!("tests/c/{program}.c")))
        .arg("-I")
        .arg(root().join("interfaces/c"))
        .arg("-L")
        .arg(&lib)
        .args(["-ltalus", "-lm"])
        .status()
        .expect("cc runs");
    assert!(
        status.success(),
        "the C test program {program} does not compile"
    );
    let run = Command::new(&out)
        .arg(root().join(scene))
        .env("LD_LIBRARY_PATH", &lib)
        .output()
        .unwrap();
    let _ = std::fs::remove_file(&out);
    let stdout = String::from_utf8_lossy(&run.stdout).into_owned();
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(
        run.status.success() && stdout.lines().any(|l| l == "ok"),
        "{stdout}\n{stderr}"
    );
    stdout
}

#[test]
fn a_c_program_drives_a_drum_through_the_c_api() {
    run_c_program("api_test", "examples/drum_fmu/drum.toml");
}

/// The fluid's arrays through the C API give the numbers of the Rust component
/// driven with the same inputs, to the last bit.
#[test]
fn a_c_program_exchanges_the_fluid_fields_through_the_c_api() {
    let scene = "tests/scenes/fluid_column.toml";
    let printed = run_c_program("fluid_test", scene);
    let mut c = talus::cosim::Component::instantiate(root(), scene).unwrap();
    let velocity = c.variable("fluid.velocity").unwrap();
    let swirl = |phase: f64| common::fluid_swirl(54, phase);
    c.set_real_vector(velocity, &swirl(0.0)).unwrap();
    c.enter_initialization_mode(0.0).unwrap();
    c.exit_initialization_mode().unwrap();
    let h = 13.0 * 2e-5;
    for k in 0..2 {
        c.set_real_vector(velocity, &swirl(0.7 * k as f64)).unwrap();
        c.do_step(k as f64 * h, h).unwrap();
    }
    let read = |name: &str| c.get_real_vector(c.variable(name).unwrap()).unwrap();
    let source = read("fluid.momentum_source");
    let mut s = [0.0; 3];
    for f in source.chunks_exact(3) {
        for d in 0..3 {
            s[d] += f[d];
        }
    }
    let phi: f64 = read("fluid.solid_fraction").iter().sum();
    let line = printed.lines().find(|l| l.starts_with("source")).unwrap();
    let numbers: Vec<f64> = line
        .split_whitespace()
        .filter_map(|w| w.parse().ok())
        .collect();
    assert_eq!(numbers, vec![s[0], s[1], s[2], phi], "{line}");
    // Per particle: the sums the C program printed, from the Rust component.
    let (ids, fluid) = c.particle_fluid().unwrap();
    let expected = format!(
        "particles {} drag {:?} slip {:?} voidage {:?} ids {}",
        ids.len(),
        fluid.iter().map(|f| f.drag.z).sum::<f64>(),
        fluid.iter().map(|f| f.slip.z).sum::<f64>(),
        fluid.iter().map(|f| f.voidage).sum::<f64>(),
        ids.iter().sum::<u64>()
    );
    let line = printed
        .lines()
        .find(|l| l.starts_with("particles"))
        .unwrap();
    let parse = |l: &str| -> Vec<f64> {
        l.split_whitespace()
            .filter_map(|w| w.parse().ok())
            .collect()
    };
    assert_eq!(parse(line), parse(&expected), "{line}");
}
