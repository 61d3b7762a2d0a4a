#!/usr/bin/env bash
# Packs the drum scene as an FMU and drives it from the fmpy master (orchestrate.py).
#   examples/drum_fmu/run.sh [2|3]
set -euo pipefail
cd "$(dirname "$0")/../.."
version="${1:-2}"
cargo build --release --locked
target/release/talus fmu examples/drum_fmu/drum.toml -o examples/drum_fmu/drum.fmu --fmi "$version"
scripts/python-env.sh examples/drum_fmu/requirements.txt
.venv/bin/python examples/drum_fmu/orchestrate.py examples/drum_fmu/drum.fmu --out examples/drum_fmu/drum_out
