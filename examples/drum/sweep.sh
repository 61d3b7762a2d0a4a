#!/usr/bin/env bash
# Runs the quasi-2D drum at several speeds and prints the drum figures of each.
#   examples/drum/sweep.sh [RPM:END_TIME:AVERAGE_AFTER ...]
# Default: 15 rpm (3.5 s, averages after 1.5 s), 45 rpm (3.0 s, after the first
# revolution), 90 rpm (2.2 s, after the first revolution). Scenes and outputs go to
# examples/drum/sweep/ (not kept in git). THREADS (default 1) threads per run; RUNS
# (default 2) runs at once.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
cases=("$@")
[ ${#cases[@]} -gt 0 ] || cases=("15:3.5:1.5" "45:3.0:" "90:2.2:")
(cd "$root" && cargo build --release --quiet)
mkdir -p "$here/sweep"
run_case() {
  IFS=: read -r rpm end after <<<"$1"
  local scene="$here/sweep/rpm$rpm.toml"
  sed -e "s/rpm = 45.0/rpm = $rpm/" -e "s/^end_time = .*/end_time = $end/" \
      -e "s|^\[drum\]|[drum]${after:+\naverage_after = $after}|" \
      "$here/quasi2d.toml" >"$scene"
  "$root/target/release/talus" run "$scene" --quiet --threads "${THREADS:-1}" \
      --out "$here/sweep/rpm${rpm}_out" >"$here/sweep/rpm$rpm.log" 2>&1
  echo "== $rpm rpm: $(tail -1 "$here/sweep/rpm$rpm.log")"
}
running=0
for c in "${cases[@]}"; do
  run_case "$c" &
  running=$((running + 1))
  if [ "$running" -ge "${RUNS:-2}" ]; then wait -n; running=$((running - 1)); fi
done
wait
for c in "${cases[@]}"; do
  rpm="${c%%:*}"
  python3 - "$here/sweep/rpm${rpm}_out/drum.json" "$rpm" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
f = lambda x, k=4: "-" if x is None else f"{x:.{k}g}"
print(f"{sys.argv[2]:>4} rpm  Fr {f(d['froude'],3)}  torque {f(d['drive_torque'])} N m "
      f"(gravity moment {f(d['gravity_moment'])})  power {f(d['power'])} W  "
      f"angle {f(d['angle_of_repose'],3)} ± {f(d['angle_of_repose_std'],2)} deg  "
      f"airborne {f(d['airborne_fraction'],2)}  flowing layer {f(d['flowing_layer'],3)} m  "
      f"over {f(d['averaged_over'],3)} s")
PY
done
