#!/usr/bin/env bash
# A profile-guided build of the talus program (about 5 minutes on two cores):
# builds talus with LLVM's instrumentation, trains it on `talus bench`'s scenes
# (the sphere pour to rest, the dodecahedron bed, the sphere bed and the many
# shapes, on one and two threads) and a short pour of beads onto dodecahedra,
# merges the profiles with the toolchain's llvm-profdata (rustup's `llvm-tools`,
# added when missing; where rustup cannot add it, Debian's llvm-N of the LLVM
# major version rustc was built with, whose profile format is rustc's), and
# builds talus again with them. The result is
# target/pgo/talus; it must write what the instrumented build wrote for the
# check pour (frames, series.csv, walls.csv byte for byte: profile guidance moves
# code, never arithmetic), or the script fails.
#   scripts/build-pgo.sh [cargo build options, e.g. --features mpi]
set -euo pipefail
cd "$(dirname "$0")/.."
work="$PWD/target/pgo"
host="$(rustc -vV | sed -n 's/^host: //p')"
profdata="$(rustc --print sysroot)/lib/rustlib/$host/bin/llvm-profdata"
if [ ! -x "$profdata" ]; then
    echo "== llvm-tools (llvm-profdata) for $(rustc --version)"
    rustup component add llvm-tools || true
fi
if [ ! -x "$profdata" ]; then
    major="$(rustc -vV | sed -n 's/^LLVM version: \([0-9]*\).*/\1/p')"
    profdata="/usr/bin/llvm-profdata-$major"
    if [ ! -x "$profdata" ]; then
        echo "== Debian's llvm-$major (llvm-profdata)"
        as_root=()
        [ "$(id -u)" -eq 0 ] || as_root=(sudo)
        "${as_root[@]}" apt-get update -qq
        DEBIAN_FRONTEND=noninteractive "${as_root[@]}" apt-get install -y -qq \
            --no-install-recommends "llvm-$major" >/dev/null
    fi
fi
rm -rf "$work/profiles" "$work/check"
mkdir -p "$work/check"

echo "== instrumented build"
RUSTFLAGS="${RUSTFLAGS:-} -Cprofile-generate=$work/profiles" \
    cargo build --release --locked --target-dir "$work/generate" --bin talus "$@"
trained="$work/generate/release/talus"

# The check pour: 60 beads from an inlet onto 32 dodecahedra in a box, 3000 steps.
sed 's/^end_time = 1.0$/end_time = 0.03/' tests/scenes/mixed_pour.toml > "$work/check/scene.toml"
grep -q '^end_time = 0.03$' "$work/check/scene.toml"

echo "== training"
"$trained" bench --scene b --threads 1 > /dev/null
"$trained" bench --scene a,c,d --threads 1 --steps 100 > /dev/null
# The instrumented counters are shared by the threads: a few steps are enough.
"$trained" bench --scene a,c --threads 2 --steps 20 > /dev/null
"$trained" run "$work/check/scene.toml" --out "$work/check/trained" --quiet > /dev/null 2>&1

echo "== build with the profiles"
"$profdata" merge -o "$work/merged.profdata" "$work/profiles"
RUSTFLAGS="${RUSTFLAGS:-} -Cprofile-use=$work/merged.profdata" \
    cargo build --release --locked --target-dir "$work/use" --bin talus "$@"
"$work/use/release/talus" run "$work/check/scene.toml" --out "$work/check/guided" --quiet > /dev/null 2>&1
# summary.json holds the run's timings: everything else must be the same bytes.
diff -r --exclude=summary.json "$work/check/trained" "$work/check/guided"
cp "$work/use/release/talus" "$work/talus"
echo "== $work/talus: the check pour's outputs are those of the instrumented build"
