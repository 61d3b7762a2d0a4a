#!/usr/bin/env bash
# On a machine with an NVIDIA GPU and its driver: builds the `cuda` feature and runs
# the kernels' tests on the real device, requiring it (a missing driver or NVRTC
# fails instead of skipping). Under five minutes on a fresh machine with Rust.
#   scripts/gpu-check.sh
# What it runs: every kernel compiled by NVRTC for sm_80 and sm_90
# (tests/cuda_kernels.rs), and the device stepper of a world of spheres on GPU 0
# against the CPU backend, 1000 steps of a converging cloud of 1000 spheres, bit for
# bit (tests/cuda_spheres.rs, `on_a_gpu_...`), besides the same through the host
# executor.
set -euo pipefail
cd "$(dirname "$0")/.."
nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader
# NVRTC: the CUDA toolkit's when installed, else PyPI's wheel.
if ! ldconfig -p | grep -q libnvrtc.so.12; then
    scripts/python-env.sh tests/python/requirements.txt
    LD_LIBRARY_PATH="$(ls -d "$PWD"/.venv/lib/python3*/site-packages/nvidia/cuda_nvrtc/lib)${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
    export LD_LIBRARY_PATH
fi
export TALUS_REQUIRE_NVRTC=1 TALUS_REQUIRE_GPU=1
cargo test --release --features cuda --test cuda_kernels --test cuda_spheres -- --nocapture
