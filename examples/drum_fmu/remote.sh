#!/usr/bin/env bash
# The drum stepped by two MPI ranks behind a zenoh node, driven by the same fmpy
# master through a proxy FMU (every FMI call forwarded to the node).
#   examples/drum_fmu/remote.sh [2|3] [RANKS]
set -euo pipefail
cd "$(dirname "$0")/../.."
version="${1:-2}"
ranks="${2:-2}"
endpoint="tcp/127.0.0.1:7447"
cargo build --release --locked --features zenoh,mpi
scripts/python-env.sh examples/drum_fmu/requirements.txt
# Open MPI refuses root unless told; CI containers run as root.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
mpirun --oversubscribe -np "$ranks" target/release/talus serve examples/drum_fmu/drum.toml \
    --key talus/drum --listen "$endpoint" --out examples/drum_fmu/remote_node_out &
node=$!
trap 'kill -TERM $node 2>/dev/null || true; wait $node 2>/dev/null || true' EXIT
target/release/talus fmu examples/drum_fmu/drum.toml -o examples/drum_fmu/drum_remote.fmu \
    --fmi "$version" --remote talus/drum --connect "$endpoint" --timeout 120
.venv/bin/python examples/drum_fmu/orchestrate.py examples/drum_fmu/drum_remote.fmu \
    --out examples/drum_fmu/remote_out
