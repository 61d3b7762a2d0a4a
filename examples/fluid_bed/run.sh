#!/usr/bin/env bash
# Packs the fluidised bed as an FMI 3.0 FMU and drives it from the plug-flow gas
# model (fluid_bed.py); writes pressure_drop.png and .csv to examples/fluid_bed/out.
#   examples/fluid_bed/run.sh [--hold 0.03]
set -euo pipefail
cd "$(dirname "$0")/../.."
cargo build --release --locked
target/release/talus fmu examples/fluid_bed/fluid_bed.toml -o examples/fluid_bed/fluid_bed.fmu --fmi 3
scripts/python-env.sh examples/drum_fmu/requirements.txt
.venv/bin/python examples/fluid_bed/fluid_bed.py examples/fluid_bed/fluid_bed.fmu --out examples/fluid_bed/out "$@"
