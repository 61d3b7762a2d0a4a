#!/usr/bin/env bash
# The MPI measurement (issue 22): scene (a) of `talus bench`, the settled bed of
# dodecahedra, on 1 and 2 threads of one process and on 1 and 2 MPI ranks of one
# thread each, alternated over ROUNDS rounds (this machine's speed drifts by up to
# 30 % between hours: compare within a round). Needs OpenMPI (scripts/system-deps.sh).
#   SCALE=0.5 STEPS=200 ROUNDS=2 benches/ranks.sh
set -euo pipefail
cd "$(dirname "$0")/.."
scale=${SCALE:-0.5}
steps=${STEPS:-200}
rounds=${ROUNDS:-2}
scripts/system-deps.sh
cargo build --release --locked --features mpi
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
talus=target/release/talus
for round in $(seq "$rounds"); do
    echo "== round $round: one process, 1 and 2 threads"
    "$talus" bench --scene a --scale "$scale" --steps "$steps" --threads 1,2
    for ranks in 1 2; do
        echo "== round $round: $ranks MPI rank(s) of one thread"
        mpirun --oversubscribe -np "$ranks" "$talus" bench --ranks --scale "$scale" \
            --steps "$steps" --threads 1
    done
done
