#!/usr/bin/env bash
# Packs a 25 mm tube, 1.8 m tall, with spheres at tube-to-sphere ratios N = 4, 6 and 10
# (the material of scene.toml, a few thousand spheres each), fed from a box that rides
# 9-18 cm above the bed with the buried bed frozen (as seed_bed.toml), and prints each
# bed's porosity and the start of its radial profile.
#   examples/fixed_bed/pack.sh              # all three
#   examples/fixed_bed/pack.sh spheres_N6   # one of them
#   THREADS=1 examples/fixed_bed/pack.sh    # threads per run (default 2)
# Scenes and outputs go to examples/fixed_bed/runs/ (not kept in git).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
(cd "$root" && cargo build --release --quiet)
mkdir -p "$here/runs"
# The [materials.*] sections of scene.toml, so the spheres stay of the pellets' material.
materials="$(awk '/^\[materials\./ { on = 1 } /^\[shapes\./ { on = 0 } on' "$here/scene.toml")"
# name : sphere radius (m) : count
cases=("spheres_N4:3.125e-3:3000" "spheres_N6:2.0833e-3:3000" "spheres_N10:1.25e-3:3000")
if [ $# -gt 0 ]; then
  wanted=()
  for c in "${cases[@]}"; do
    for name in "$@"; do [ "${c%%:*}" = "$name" ] && wanted+=("$c"); done
  done
  [ ${#wanted[@]} -gt 0 ] || { echo "no case named $*" >&2; exit 2; }
  cases=("${wanted[@]}")
fi
for c in "${cases[@]}"; do
  IFS=: read -r name radius count <<<"$c"
  scene="$here/runs/$name.toml"
  cat >"$scene" <<TOML
# Written by pack.sh: $count spheres of radius $radius m in a 25 mm tube.
[simulation]
dt = "auto"
end_time = 15.0
gravity = [0.0, 0.0, -9.81]
seed = 21
settle = { max_speed = 5e-3, kinetic_energy_per_particle = 1e-9, hold = 0.05 }

[output]
frame_interval = 0.5
csv_interval = 0.01

# The materials of scene.toml:
$materials

[shapes.ball]
kind = "sphere"
radius = $radius

[[wall]]
name = "tube"
material = "steel"
geometry = { kind = "cylinder", base = [0.0, 0.0, 0.0], axis = [0.0, 0.0, 1.0], length = 1.8, radius = 0.0125, sides = 96, bottom = true }

[[inlet]]
shape = "ball"
material = "pellet"
min = [-0.0085, -0.0085, 0.09]
max = [0.0085, 0.0085, 0.18]
rate = 3000.0
count = $count
velocity = [0.0, 0.0, -0.5]
above_bed = true

[bed]
base = [0.0, 0.0, 0.0]
axis = [0.0, 0.0, 1.0]
radius = 0.0125
freeze = { depth = 0.06, max_speed = 0.01 }
TOML
  "$root/target/release/talus" run "$scene" --quiet --threads "${THREADS:-2}" \
      --out "$here/runs/${name}_out" | tee "$here/runs/$name.log"
done
for c in "${cases[@]}"; do
  name="${c%%:*}"
  python3 - "$here/runs/${name}_out" "$name" <<'PY'
import json, sys
d = json.load(open(sys.argv[1] + "/packing.json"))
s = json.load(open(sys.argv[1] + "/summary.json"))
prof = " ".join(f"{b['porosity']:.2f}" for b in d["radial"][::-1][:20:2])
print(f"{sys.argv[2]:>14}: {d['particles']} particles, N = {d['tube_to_particle']:.2f}, "
      f"height {d['bed_height']*1e3:.1f} mm, porosity {d['porosity']:.4f} "
      f"(±{d['volume_error']/d['solid_volume']:.1e}) over {d['region'][0]*1e3:.1f}-{d['region'][1]*1e3:.1f} mm, "
      f"coordination {d['coordination_mean']:.2f}, {s['frozen']} frozen, "
      f"{s['ended_by']} at {s['time']:.2f} s in {s['wall_clock_s']:.0f} s (dt {s['dt']:.2e} s)")
print(f"{'':>14}  eps from the wall inwards, every 2nd bin of d/20: {prof}")
PY
done
