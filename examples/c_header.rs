//! Writes `interfaces/c/talus.h` from the `extern "C"` functions of `src/ffi/mod.rs`
//! with cbindgen (configuration: `interfaces/c/cbindgen.toml`), doc comments carried
//! over. Run after changing the C API:
//!
//!     cargo run --example c_header
//!
//! The test `c_api::the_header_is_what_cbindgen_generates` compares the committed
//! header with what this writes.

use std::path::Path;

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let header = root.join("interfaces/c/talus.h");
    let written = c_header(root).write_to_file(&header);
    println!(
        "{} {}",
        if written { "wrote" } else { "unchanged:" },
        header.display()
    );
}

/// The header as cbindgen generates it.
pub fn c_header(root: &Path) -> cbindgen::Bindings {
    let config = cbindgen::Config::from_file(root.join("interfaces/c/cbindgen.toml"))
        .expect("interfaces/c/cbindgen.toml reads");
    cbindgen::Builder::new()
        .with_config(config)
        .with_src(root.join("src/ffi/mod.rs"))
        .generate()
        .expect("cbindgen parses src/ffi/mod.rs")
}
