#!/usr/bin/env bash
# Two builds of `plenum bench` at the same moment, one thread each on its own core, cores
# swapped every round: whatever else the machine does slows both alike, so their ratio holds
# where run-to-run times drift by ±15 %. Prints each round and the ratio B/A of the sums.
#
#   docs/bench/side_by_side.sh A B ACCEL MESH RAYS [ROUNDS]
#   docs/bench/side_by_side.sh /tmp/plenum-old target/release/plenum grid \
#       ../shared/data/meshes/dragon-100k.obj dragon-primary.rays 4
#
# Best for rays whose cost is computation (camera rays); incoherent rays on large meshes
# share the last-level cache between the two and read noisier.
set -euo pipefail
if [ $# -lt 5 ]; then
  sed -n '2,12p' "$0" >&2
  exit 2
fi
a=$1 b=$2 accel=$3 mesh=$4 rays=$5 rounds=${6:-4}
figures() { grep -E '^(closest|any)' | awk '{printf "%s ", $3}'; }
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
for round in $(seq "$rounds"); do
  core_a=$(( round % 2 )) core_b=$(( (round + 1) % 2 ))
  taskset -c "$core_a" "$a" bench --mesh "$mesh" --rays "$rays" --accel "$accel" --threads 1 2>&1 | figures > "$out/a" &
  taskset -c "$core_b" "$b" bench --mesh "$mesh" --rays "$rays" --accel "$accel" --threads 1 2>&1 | figures > "$out/b"
  wait
  echo "A $(cat "$out/a")  B $(cat "$out/b")"
done | awk '{ print; a1 += $2; a2 += $3; b1 += $5; b2 += $6 }
  END { printf "B/A closest %.3f, any %.3f (Mrays/s, one thread each)\n", b1 / a1, b2 / a2 }'
