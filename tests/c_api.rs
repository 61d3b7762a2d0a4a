//! The native C API: the header is cbindgen's and matches the exported functions,
//! and a C program compiled against it drives a drum scene (results, misuse,
//! rollback).

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::Command;

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

#[test]
fn a_c_program_drives_a_drum_through_the_c_api() {
    let lib = library_dir();
    assert!(
        lib.join("libtalus.so").exists(),
        "no libtalus.so in {}",
        lib.display()
    );
    let out = std::env::temp_dir().join(format!("talus-api-test-{}", std::process::id()));
    let status = Command::new("cc")
        .args(["-std=c99", "-Wall", "-Wextra", "-Werror", "-o"])
        .arg(&out)
        .arg(root().join("tests/c/api_test.c"))
        .arg("-I")
        .arg(root().join("interfaces/c"))
        .arg("-L")
        .arg(&lib)
        .args(["-ltalus", "-lm"])
        .status()
        .expect("cc runs");
    assert!(status.success(), "the C test program does not compile");
    let run = Command::new(&out)
        .arg(root().join("examples/drum_fmu/drum.toml"))
        .env("LD_LIBRARY_PATH", &lib)
        .output()
        .unwrap();
    let _ = std::fs::remove_file(&out);
    let stdout = String::from_utf8_lossy(&run.stdout);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(
        run.status.success() && stdout.contains("ok"),
        "{stdout}\n{stderr}"
    );
}
