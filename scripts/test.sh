#!/usr/bin/env bash
# Installs what the tests need and runs them all. This is the README's test command,
# and what CI runs (.ci/run).
set -euo pipefail
cd "$(dirname "$0")/.."

# The Rust toolchain is the machine's own; rustfmt and clippy come with it. Feature
# sets built: default (no zenoh) and `zenoh` (the transport; its protoc is vendored).
echo "== format"
cargo fmt --check
echo "== clippy (default features, then --features zenoh)"
cargo clippy --all-targets --locked -- -D warnings
cargo clippy --all-targets --locked --features zenoh -- -D warnings
echo "== build (the talus program and libtalus.so, used by the C, FMU and zenoh tests)"
cargo build --locked --features zenoh
echo "== tests (--features zenoh: everything)"
cargo test --locked --all-targets --features zenoh
echo "== benchmarks build"
cargo bench --locked --no-run
echo "== Python tests (fmpy, zenoh client)"
scripts/python-env.sh tests/python/requirements.txt
.venv/bin/python -m pytest tests/python -q
