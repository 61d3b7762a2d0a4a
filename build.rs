//! Generates the protobuf types of the zenoh transport (feature `zenoh`) with the
//! vendored protoc, so no system protoc is needed; compiles the CUDA kernels as C++
//! for the host executor (feature `cuda`).

fn main() {
    #[cfg(feature = "cuda")]
    {
        println!("cargo:rerun-if-changed=kernels");
        // No contraction into fused multiply-adds: the host executor computes what
        // the CPU backend computes, operation by operation.
        cc::Build::new()
            .cpp(true)
            .file("kernels/host.cpp")
            .include("kernels")
            .flag("-std=c++17")
            .flag("-ffp-contract=off")
            .warnings(true)
            .extra_warnings(true)
            .warnings_into_errors(true)
            .compile("talus_kernels_host");
    }
    #[cfg(feature = "zenoh")]
    {
        println!("cargo:rerun-if-changed=proto/talus/v1/talus.proto");
        let protoc = match std::env::var_os("PROTOC") {
            Some(p) => std::path::PathBuf::from(p),
            None => protoc_bin_vendored::protoc_bin_path().expect("vendored protoc"),
        };
        // `talus proto --python-out` runs the same protoc.
        println!("cargo:rustc-env=TALUS_PROTOC={}", protoc.display());
        prost_build::Config::new()
            .protoc_executable(protoc)
            .compile_protos(&["proto/talus/v1/talus.proto"], &["proto"])
            .expect("compiling proto/talus/v1/talus.proto");
    }
}
