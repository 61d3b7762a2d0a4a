#!/usr/bin/env bash
# Creates the project's Python environment (.venv) and installs the given
# requirement files into it. Used by the test script and the Python examples.
#   scripts/python-env.sh tests/python/requirements.txt [more.txt ...]
set -euo pipefail
cd "$(dirname "$0")/.."
if [ ! -x .venv/bin/python ]; then
    python3 -m venv .venv
fi
for req in "$@"; do
    .venv/bin/pip install --quiet --disable-pip-version-check -r "$req"
done
