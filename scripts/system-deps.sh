#!/usr/bin/env bash
# Installs the Debian packages the tests need, where missing: OpenMPI (headers, and
# mpirun for the tests that run ranks), libclang, with which the `mpi` crate
# generates its bindings, and g++, which compiles the CUDA kernels for the host
# executor. Uses sudo when not root.
set -euo pipefail
packages=(libopenmpi-dev openmpi-bin libclang-dev g++)
missing=()
for p in "${packages[@]}"; do
    dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
    exit 0
fi
echo "installing ${missing[*]}"
as_root=()
[ "$(id -u)" -eq 0 ] || as_root=(sudo)
export DEBIAN_FRONTEND=noninteractive
"${as_root[@]}" apt-get update -qq
"${as_root[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
