#!/usr/bin/env bash
# Builds the talus Python module (release wheel, maturin) into .venv and runs drum.py.
#   examples/python/run.sh [--rpm 30] [--end 3]
set -euo pipefail
cd "$(dirname "$0")/../.."
scripts/python-env.sh examples/python/requirements.txt
.venv/bin/pip install --quiet "maturin>=1.5,<2"
rm -rf target/wheels
.venv/bin/maturin build --release -m python/Cargo.toml --strip --out target/wheels
.venv/bin/pip install --quiet --force-reinstall --no-deps target/wheels/talus-*-abi3-*.whl
.venv/bin/python examples/python/drum.py "$@"
