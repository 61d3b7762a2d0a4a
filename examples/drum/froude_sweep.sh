#!/usr/bin/env bash
# The quasi-2D drum over Froude numbers: runs quasi2d.toml at each Froude number
# (the shell's speed ω = √(Fr g / R)), and the same with the end plates' friction
# halved (the plates' material at μ = 0, so particle–plate pairs take 0.35), then
# draws the regimes talus names against Mellmann's bands (regime_map.png).
#   examples/drum/froude_sweep.sh [FROUDE:END_TIME ...]
# Default: 1e-4 (15 s simulated) … 1.5 (5 s); averages after 1 s. Scenes and outputs go to
# examples/drum/froude/ (not kept in git). RUNS (default 2) runs at once, one thread
# each; about an hour on two cores.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
cases=("$@")
[ ${#cases[@]} -gt 0 ] || cases=(0.0001:15 0.001:10 0.01:6 0.03:5 0.1:3 0.2:3 0.6:3 1.0:5 1.5:5)
(cd "$root" && cargo build --release --quiet)
"$root/scripts/python-env.sh" "$here/requirements.txt"
out="$here/froude"
mkdir -p "$out"
scene() { # FROUDE END PLATES → the scene's text
    local rpm
    rpm=$(python3 -c "import math; print(round(math.sqrt($1 * 9.81 / 0.15) * 60 / (2 * math.pi), 3))")
    sed -e "s/rpm = 45.0/rpm = $rpm/" -e "s/^end_time = .*/end_time = $2/" \
        -e "s/^frame_interval = .*/frame_interval = 0.1/" \
        -e "s|^\[drum\]|[drum]\naverage_after = 1.0|" "$here/quasi2d.toml" |
    if [ "$3" = smooth ]; then
        python3 -c "
import sys
s = sys.stdin.read()
s = s.replace('[materials.plate]', '[materials.glass]\ndensity = 1500.0\nyoung = 1e6\npoisson = 0.1\nrestitution = 0.1\nfriction = 0.0\n\n[materials.plate]', 1)
for name in ('front', 'back'):
    i = s.index(f'name = \"{name}\"'); j = s.index('material = \"plate\"', i)
    s = s[:j] + 'material = \"glass\"' + s[j + len('material = \"plate\"'):]
print(s, end='')"
    else
        cat
    fi
}
run_case() {
    IFS=: read -r fr end plates <<<"$1"
    scene "$fr" "$end" "$plates" >"$out/${plates}_fr$fr.toml"
    "$root/target/release/talus" run "$out/${plates}_fr$fr.toml" --quiet --threads 1 \
        --out "$out/${plates}_fr$fr" >"$out/${plates}_fr$fr.log" 2>&1
    echo "== $plates plates, Fr $fr: $(python3 -c "import json; print(json.load(open('$out/${plates}_fr$fr/drum.json'))['regime'])")"
}
running=0
for plates in rough smooth; do
    for c in "${cases[@]}"; do
        run_case "$c:$plates" &
        running=$((running + 1))
        if [ "$running" -ge "${RUNS:-2}" ]; then wait -n; running=$((running - 1)); fi
    done
done
wait
dirs() { for c in "${cases[@]}"; do printf '%s ' "$out/$1_fr${c%%:*}"; done; }
"$root/.venv/bin/python" "$here/regime_map.py" "$here/regime_map.png" \
    "the example (plates μ 0.7)=$(dirs rough)" "plates' friction halved=$(dirs smooth)"
