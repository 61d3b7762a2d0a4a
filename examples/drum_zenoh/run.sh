#!/usr/bin/env bash
# Serves the drum scene over zenoh and drives it from orchestrate.py.
#   examples/drum_zenoh/run.sh
set -euo pipefail
cd "$(dirname "$0")/../.."
cargo build --release --locked --features zenoh
scripts/python-env.sh interfaces/python/requirements.txt examples/drum_zenoh/requirements.txt
target/release/talus proto --python-out examples/drum_zenoh/gen
target/release/talus serve examples/drum_fmu/drum.toml --key talus/drum \
    --listen tcp/127.0.0.1:7447 --out examples/drum_zenoh/serve_out &
server=$!
trap 'kill -TERM $server 2>/dev/null; wait $server' EXIT
.venv/bin/python examples/drum_zenoh/orchestrate.py --key talus/drum \
    --connect tcp/127.0.0.1:7447 --proto examples/drum_zenoh/gen --out examples/drum_zenoh/drum_out
