//! The kernels compiled to PTX by NVRTC, which needs no GPU: cudarc loads
//! `libnvrtc` at run time (the CUDA toolkit's, or PyPI's `nvidia-cuda-nvrtc-cu12`
//! with its `lib` directory on `LD_LIBRARY_PATH`).

use std::collections::HashMap;
use std::sync::{Arc, Mutex, MutexGuard, OnceLock};

use super::KernelFile;

/// The GPU architectures every kernel is compiled for: Ampere (A100) and Hopper
/// (H100, H200).
pub const ARCHITECTURES: [&str; 2] = ["sm_80", "sm_90"];

/// Why a kernel was not compiled.
#[derive(Debug, thiserror::Error)]
pub enum NvrtcError {
    /// No NVRTC library could be loaded.
    #[error(
        "NVRTC (libnvrtc) is not found: install the CUDA toolkit, or `pip install \
         nvidia-cuda-nvrtc-cu12` and put its nvidia/cuda_nvrtc/lib on LD_LIBRARY_PATH"
    )]
    Missing,
    /// NVRTC refused the source.
    #[error("kernels/{file}: NVRTC for {arch}: {log}")]
    Compile {
        /// The source file.
        file: &'static str,
        /// The architecture.
        arch: String,
        /// What NVRTC said.
        log: String,
    },
}

/// Whether an NVRTC library can be loaded.
pub fn is_present() -> bool {
    // SAFETY: only tries to open the library (cudarc panics on a missing one later).
    unsafe { cudarc::nvrtc::sys::is_culib_present() }
}

/// PTX of each kernel file and architecture compiled in this process, with how
/// many times each was compiled.
type Cache = HashMap<(&'static str, String), (Arc<str>, usize)>;

fn cache() -> MutexGuard<'static, Cache> {
    static CACHE: OnceLock<Mutex<Cache>> = OnceLock::new();
    let cache = CACHE.get_or_init(Mutex::default);
    // A panic while the lock was held left the map whole: every insertion is one call.
    cache
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// The kernel file compiled to PTX for `arch` (`"sm_80"`, `"sm_90"`, ...), once per
/// process: a device opened again (a component reset, a second simulation) takes
/// the PTX of the first compilation.
pub fn compile(file: &KernelFile, arch: &str) -> Result<Arc<str>, NvrtcError> {
    let key = (file.name, arch.to_owned());
    if let Some((ptx, _)) = cache().get(&key) {
        return Ok(ptx.clone());
    }
    // Compiled without the lock: files compile in parallel, and two threads asking for
    // the same one at once both compile it (the same text).
    let ptx: Arc<str> = compile_uncached(file, arch)?.into();
    let mut cache = cache();
    let entry = cache.entry(key).or_insert_with(|| (ptx, 0));
    entry.1 += 1;
    Ok(entry.0.clone())
}

/// How many times this process compiled `file` for `arch` (see [`compile`]).
pub fn compilations(file: &KernelFile, arch: &str) -> usize {
    cache()
        .get(&(file.name, arch.to_owned()))
        .map_or(0, |(_, count)| *count)
}

/// The kernel file compiled to PTX for `arch`, without the cache.
fn compile_uncached(file: &KernelFile, arch: &str) -> Result<String, NvrtcError> {
    let headers: String = file
        .headers
        .iter()
        .map(|h| format!("#line 1 \"{}\"\n{}\n", h.name, h.source))
        .collect();
    compile_source(
        file.name,
        &format!("{headers}#line 1 \"{}\"\n{}", file.name, file.source),
        arch,
    )
}

/// The text `source` of the file `file` compiled to PTX for `arch`, in double
/// precision with IEEE division and square roots and without contraction into fused
/// multiply–adds (so a kernel computes what the CPU backend computes, operation by
/// operation).
pub fn compile_source(file: &'static str, source: &str, arch: &str) -> Result<String, NvrtcError> {
    if !is_present() {
        return Err(NvrtcError::Missing);
    }
    let options = cudarc::nvrtc::CompileOptions {
        prec_div: Some(true),
        prec_sqrt: Some(true),
        ftz: Some(false),
        fmad: Some(false),
        name: Some(file.into()),
        options: vec![format!("--gpu-architecture={arch}")],
        ..Default::default()
    };
    cudarc::nvrtc::compile_ptx_with_opts(source, options)
        .map(|ptx| ptx.to_src())
        .map_err(|e| NvrtcError::Compile {
            file,
            arch: arch.to_owned(),
            log: match e {
                cudarc::nvrtc::CompileError::CompileError { log, .. } => {
                    log.to_string_lossy().into_owned()
                }
                other => format!("{other:?}"),
            },
        })
}
