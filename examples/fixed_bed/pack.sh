#!/usr/bin/env bash
# Packs the tube of scene.toml with spheres at tube-to-sphere ratios N = 4, 6 and 10
# (and, with PELLETS=1, with the scene's cylindrical pellets) and prints each bed's
# porosity and the start of its radial profile.
#   examples/fixed_bed/pack.sh            # spheres
#   PELLETS=1 examples/fixed_bed/pack.sh  # also the pellets (hours on 2 cores)
# Scenes and outputs go to examples/fixed_bed/runs/ (not kept in git).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
(cd "$root" && cargo build --release --quiet)
mkdir -p "$here/runs"
# name : sphere radius (m) : count : inlet bottom (m)
cases=("spheres_N4:3.125e-3:500:0.30" "spheres_N6:2.0833e-3:1500:0.22" "spheres_N10:1.25e-3:3000:0.10")
[ "${PELLETS:-0}" = 1 ] && cases+=("pellets_N4.5:pellet:300:0.16")
for c in "${cases[@]}"; do
  IFS=: read -r name radius count bottom <<<"$c"
  scene="$here/runs/$name.toml"
  if [ "$radius" = pellet ]; then
    sed -e "s/^count = .*/count = $count/" "$here/scene.toml" >"$scene"
  else
    sed -e "s/^radius = 3.148e-3/radius = $radius/" -e "s/^shape = \"pellet\"/shape = \"sphere\"/" \
        -e "s/^count = .*/count = $count/" -e "s/^rate = .*/rate = 3000.0/" \
        -e "s/^min = \[-0.0085, -0.0085, 0.16\]/min = [-0.0085, -0.0085, $bottom]/" \
        -e "s/^end_time = .*/end_time = 6.0/" -e "s/^length = 5.5e-3/length = 5.5e-3/" \
        "$here/scene.toml" | sed -e "s/^max = \[0.0085, 0.0085, 0.3\]/max = [0.0085, 0.0085, 0.6]/" \
        -e "s/length = 0.3, radius = 0.0125/length = 0.6, radius = 0.0125/" >"$scene"
  fi
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
      f"(±{d['volume_error']/d['solid_volume']:.1e}), coordination {d['coordination_mean']:.2f}, "
      f"{s['ended_by']} at {s['time']:.2f} s in {s['wall_clock_s']:.0f} s (dt {s['dt']:.2e} s)")
print(f"{'':>14}  eps from the wall inwards, every 2nd bin of d/20: {prof}")
PY
done
