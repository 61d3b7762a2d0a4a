#!/usr/bin/env bash
# On a machine with an NVIDIA GPU and its driver: the kernels compiled by NVRTC, the
# parity tests on the real device (a missing driver or NVRTC fails instead of
# skipping), and `talus bench --backend cuda` on the sphere scenes at 5000, 100 000
# and a million spheres and on the settled bed of dodecahedra at 10 000 and, tiled, a
# million. Under five minutes with the binaries built.
#   scripts/gpu-check.sh              builds the `cuda` feature with cargo, then runs
#   scripts/gpu-check.sh BIN_DIR      runs binaries built elsewhere (a GPU machine
#                                     without Rust): BIN_DIR holds `talus` and the
#                                     test binaries cuda_kernels, cuda_spheres,
#                                     cuda_backend and cuda_polyhedra (`cargo test --release --features
#                                     cuda --no-run` names them, with a hash)
# What it runs: every kernel compiled by NVRTC for sm_80 and sm_90
# (tests/cuda_kernels.rs); the converging cloud, the cloud thrown into a box (both
# also under the volume law, the thrown one with either rolling resistance) and the
# turning drum on GPU 0 against the CPU backend, the particles to the bit and the
# sums to 1e-12 (tests/cuda_spheres.rs, `on_a_gpu_...`); the backend under a whole
# simulation through the host executor (tests/cuda_backend.rs); the polyhedra's
# overlaps and facet overlaps on GPU 0 against the CPU's, and a pour and a drum of
# polyhedra stepped on GPU 0 against the CPU backend to round-off
# (tests/cuda_polyhedra.rs, `on_a_gpu_...`); the benchmark.
set -euo pipefail
cd "$(dirname "$0")/.."
nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader
# NVRTC: the CUDA toolkit's when installed (cudarc opens libnvrtc.so), else PyPI's.
if ! ldconfig -p | grep -qE 'libnvrtc\.so(\.12)? '; then
    toolkit=$(ls /usr/local/cuda*/targets/x86_64-linux/lib/libnvrtc.so.1[23] 2>/dev/null | head -1 || true)
    if [ -n "$toolkit" ]; then
        link="$(mktemp -d)"
        ln -s "$toolkit" "$link/libnvrtc.so"
        LD_LIBRARY_PATH="$link:$(dirname "$toolkit")${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
    else
        scripts/python-env.sh tests/python/requirements.txt
        LD_LIBRARY_PATH="$(ls -d "$PWD"/.venv/lib/python3*/site-packages/nvidia/cuda_nvrtc/lib)${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
    fi
    export LD_LIBRARY_PATH
fi
export TALUS_REQUIRE_NVRTC=1 TALUS_REQUIRE_GPU=1
if [ $# -ge 1 ]; then
    bin="$1"
    talus="$bin/talus"
    "$bin/cuda_kernels" --nocapture
    "$bin/cuda_spheres" on_a_gpu --nocapture
    "$bin/cuda_backend"
    "$bin/cuda_polyhedra" on_a_gpu --nocapture
else
    cargo test --release --features cuda --test cuda_kernels --test cuda_spheres \
        --test cuda_backend --test cuda_polyhedra -- --nocapture
    cargo build --release --features cuda --bin talus
    talus=target/release/talus
fi
bench="$talus bench --backend cuda --threads 1"
$bench --scene b,c --steps 400
$bench --scene c --scale 20 --steps 300
$bench --scene c --scale 200 --steps 100
$bench --scene a --steps 200
$bench --scene a --scale 100 --steps 50
