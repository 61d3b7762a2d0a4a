#!/usr/bin/env bash
# Registers and spills of every CUDA kernel, as ptxas assembles NVRTC's PTX for
# sm_80 and sm_90 (no GPU needed): installs PyPI's nvidia-cuda-nvcc-cu12 (ptxas)
# into .venv, has the kernels' compile test write the PTX, and prints a table.
#   scripts/ptxas-report.sh
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/python-env.sh tests/python/requirements.txt
.venv/bin/pip install --quiet --disable-pip-version-check nvidia-cuda-nvcc-cu12==12.9.86
site="$(ls -d "$PWD"/.venv/lib/python3*/site-packages)"
export LD_LIBRARY_PATH="$site/nvidia/cuda_nvrtc/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
ptx="$(mktemp -d)"
trap 'rm -rf "$ptx"' EXIT
TALUS_REQUIRE_NVRTC=1 TALUS_PTX_DIR="$ptx" cargo test --quiet --features cuda --test cuda_kernels >/dev/null
echo "| kernel | arch | registers | spill stores | spill loads | stack (bytes) |"
echo "| --- | --- | --- | --- | --- | --- |"
for f in "$ptx"/*.ptx; do
    arch="${f%.ptx}"; arch="${arch##*.}"
    "$site/nvidia/cuda_nvcc/bin/ptxas" -v --gpu-name "$arch" -o /dev/null "$f" 2>&1 |
    awk -v arch="$arch" '
        /Function properties for/ { name = $NF }
        /bytes stack frame/ { stack = $1; stores = $5; loads = $9 }
        /Used [0-9]+ registers/ { for (i = 1; i <= NF; i++) if ($i == "Used") regs = $(i + 1);
            printf "| %s | %s | %s | %s | %s | %s |\n", name, arch, regs, stores, loads, stack }'
done | sort
