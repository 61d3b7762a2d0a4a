//! The CUDA kernels compile with NVRTC (no GPU needed) for every architecture talus
//! supports, once per process, and a kernel NVRTC refuses is reported with its file
//! and NVRTC's log.
//! Where no NVRTC library is found the test says so and passes, unless
//! `TALUS_REQUIRE_NVRTC` is set, as the test script sets it after installing PyPI's
//! `nvidia-cuda-nvrtc-cu12`.
#![cfg(feature = "cuda")]

use talus::engine::cuda::nvrtc::{
    ARCHITECTURES, NvrtcError, compilations, compile, compile_source, is_present,
};
use talus::engine::cuda::{FILES, Kernel};

#[test]
fn every_kernel_compiles_with_nvrtc_for_every_architecture() {
    if !is_present() {
        assert!(
            std::env::var_os("TALUS_REQUIRE_NVRTC").is_none(),
            "TALUS_REQUIRE_NVRTC is set: {}",
            NvrtcError::Missing
        );
        eprintln!("skipped: {}", NvrtcError::Missing);
        return;
    }
    for file in &FILES {
        for arch in ARCHITECTURES {
            let ptx = compile(file, arch).unwrap_or_else(|e| panic!("{e}"));
            // scripts/ptxas-report.sh reads the PTX from here.
            if let Some(dir) = std::env::var_os("TALUS_PTX_DIR") {
                let name = format!("{}.{arch}.ptx", file.name.trim_end_matches(".cu"));
                std::fs::write(std::path::Path::new(&dir).join(name), ptx.as_bytes()).unwrap();
            }
            assert!(ptx.contains(&format!(".target {arch}")), "{arch}");
            let kernels = Kernel::ALL
                .into_iter()
                .filter(|k| k.file().name == file.name);
            for kernel in kernels {
                assert!(
                    ptx.contains(&format!(".entry {}(", kernel.name())),
                    "{} in {arch}'s PTX of {}",
                    kernel.name(),
                    file.name
                );
            }
        }
    }
    // Compiled once per process: asked again, the same text without NVRTC.
    for file in &FILES {
        for arch in ARCHITECTURES {
            let first = compile(file, arch).unwrap();
            assert!(std::sync::Arc::ptr_eq(
                &first,
                &compile(file, arch).unwrap()
            ));
            assert_eq!(compilations(file, arch), 1, "{} for {arch}", file.name);
        }
    }
    // Every kernel belongs to a file that was compiled.
    assert!(
        Kernel::ALL
            .iter()
            .all(|k| FILES.iter().any(|f| k.file().name == f.name))
    );
    let broken = "extern \"C\" __global__ void k(double* x) { x[0] = undeclared; }";
    let err = compile_source("broken.cu", broken, "sm_80").unwrap_err();
    let said = err.to_string();
    // The message names the file and its own line (after the prepended helpers).
    assert!(
        said.starts_with("kernels/broken.cu: NVRTC for sm_80: ")
            && said.contains("undeclared")
            && said.contains("broken.cu(1)"),
        "{said}"
    );
}
