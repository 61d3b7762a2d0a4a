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
