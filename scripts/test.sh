#!/usr/bin/env bash
# Installs what the tests need and runs them all. This is the README's test command,
# and what CI runs (.ci/run).
set -euo pipefail
cd "$(dirname "$0")/.."

# The Rust toolchain is the machine's own; rustfmt and clippy come with it. Feature
# sets built: default (no zenoh, no MPI, no CUDA) and `zenoh,mpi,cuda` (the
# transport, its protoc vendored; MPI ranks over Debian's OpenMPI; the CUDA kernels,
# compiled by NVRTC from PyPI and run on the CPU by the host executor). The
# workspace's second member, python/, is the Python module (PyO3).
echo "== system packages (OpenMPI, libclang)"
scripts/system-deps.sh
echo "== format"
cargo fmt --all --check
echo "== clippy (default features, then --features zenoh,mpi,cuda, then the Python module)"
cargo clippy --all-targets --locked -- -D warnings
cargo clippy --all-targets --locked --features zenoh,mpi,cuda -- -D warnings
cargo clippy -p talus-python --all-targets --locked -- -D warnings
echo "== build (the talus program and libtalus.so, used by the C, FMU and zenoh tests)"
cargo build --locked --features zenoh,mpi,cuda
echo "== Python environment (fmpy, zenoh client, maturin, NVRTC)"
scripts/python-env.sh tests/python/requirements.txt
# NVRTC from PyPI (no GPU needed): cudarc opens libnvrtc.so.12 from the library path,
# and the kernels' compile test must find it.
LD_LIBRARY_PATH="$(ls -d "$PWD"/.venv/lib/python3*/site-packages/nvidia/cuda_nvrtc/lib)${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
export LD_LIBRARY_PATH
export TALUS_REQUIRE_NVRTC=1
echo "== tests (--features zenoh,mpi,cuda: everything; the MPI tests start mpirun themselves)"
cargo test --locked --all-targets --features zenoh,mpi,cuda
echo "== benchmarks build"
cargo bench --locked --no-run
echo "== profile-guided build (scripts/build-pgo.sh: trained, rebuilt, the check pour's outputs unchanged)"
scripts/build-pgo.sh
echo "== the Python module: an abi3 wheel built by maturin, installed into .venv"
rm -rf target/wheels
.venv/bin/maturin build --locked -m python/Cargo.toml --profile dev --strip --out target/wheels
.venv/bin/pip install --quiet --force-reinstall --no-deps target/wheels/talus-*-abi3-*.whl
echo "== Python tests (FMUs under fmpy, the zenoh client, the talus module)"
.venv/bin/python -m pytest tests/python -q
echo "== disk taken by the build: $(du -sh target | cut -f1) in target/"
