#!/usr/bin/env bash
# Installs what the tests need and runs them all. This is the README's test command,
# and what CI runs (.ci/run).
set -euo pipefail
cd "$(dirname "$0")/.."

# The Rust toolchain is the machine's own; rustfmt and clippy come with it.
echo "== format"
cargo fmt --check
echo "== clippy"
cargo clippy --all-targets --locked -- -D warnings
echo "== tests"
cargo test --locked --all-targets
echo "== benchmarks build"
cargo bench --locked --no-run
echo "== Python tests (fmpy)"
# The talus program and libtalus.so they pack into FMUs (built by the tests above;
# this only makes sure).
cargo build --locked
scripts/python-env.sh tests/python/requirements.txt
.venv/bin/python -m pytest tests/python -q
