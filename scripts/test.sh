#!/usr/bin/env bash
# Installs what the tests need and runs them all. This is the README's test command,
# and what CI runs (.ci/run).
set -euo pipefail
cd "$(dirname "$0")/.."

# The Rust toolchain is the machine's own; rustfmt and clippy come with it. Feature
# sets built: default (no zenoh, no MPI) and `zenoh,mpi` (the transport, its protoc
# vendored; MPI ranks over Debian's OpenMPI). The workspace's second member,
# python/, is the Python module (PyO3).
echo "== system packages (OpenMPI, libclang)"
scripts/system-deps.sh
echo "== format"
cargo fmt --all --check
echo "== clippy (default features, then --features zenoh,mpi, then the Python module)"
cargo clippy --all-targets --locked -- -D warnings
cargo clippy --all-targets --locked --features zenoh,mpi -- -D warnings
cargo clippy -p talus-python --all-targets --locked -- -D warnings
echo "== build (the talus program and libtalus.so, used by the C, FMU and zenoh tests)"
cargo build --locked --features zenoh,mpi
echo "== tests (--features zenoh,mpi: everything; the MPI tests start mpirun themselves)"
cargo test --locked --all-targets --features zenoh,mpi
echo "== benchmarks build"
cargo bench --locked --no-run
echo "== Python environment (fmpy, zenoh client, maturin)"
scripts/python-env.sh tests/python/requirements.txt
echo "== the Python module: an abi3 wheel built by maturin, installed into .venv"
rm -rf target/wheels
.venv/bin/maturin build --locked -m python/Cargo.toml --profile dev --strip --out target/wheels
.venv/bin/pip install --quiet --force-reinstall --no-deps target/wheels/talus-*-abi3-*.whl
echo "== Python tests (FMUs under fmpy, the zenoh client, the talus module)"
.venv/bin/python -m pytest tests/python -q
echo "== disk taken by the build: $(du -sh target | cut -f1) in target/"
