#!/usr/bin/env bash
# The BVH against Embree in one process, cell by cell: each run of `plenum bench --baseline
# embree` times the two in turn, pass for pass, so the machine's drift from one moment to
# the next falls on both alike; ROUNDS runs per cell give the mean and the range of the
# ratios (above 1: the BVH is faster). Ratios move by ±5 % from one run to the next on
# the project's machines, so read the mean of several rounds.
#
#   docs/bench/against_embree.sh PLENUM [WORK] [ROUNDS]
#   cargo build --release -p plenum-cli --features embree   # needs libembree-dev
#   docs/bench/against_embree.sh target/release/plenum /tmp/one-run 10
#   MESHES=ico KINDS=incoherent THREADS=1 docs/bench/against_embree.sh target/release/plenum
#
# MESHES (bunny dragon ico; default bunny dragon), KINDS (primary incoherent) and THREADS
# (default 2) choose the cells. Rays and the icosphere are made in WORK (default
# /tmp/one-run) the first time, as by one_run.sh; raw JSON lines go to WORK/against.jsonl.
set -euo pipefail
if [ $# -lt 1 ]; then
  sed -n '2,15p' "$0" >&2
  exit 2
fi
plenum=$(realpath "$1") work=${2:-/tmp/one-run} rounds=${3:-5}
here=$(dirname "$(realpath "$0")")
shared=$(realpath "$here/../../../shared")
mkdir -p "$work"
cd "$work"
declare -A meshes=(
  [bunny]=$shared/data/meshes/stanford-bunny.obj
  [dragon]=$shared/data/meshes/dragon-100k.obj
  [ico]=$work/ico8.ply
)
out=$work/against.jsonl
: > "$out"
for round in $(seq "$rounds"); do
  for name in ${MESHES:-bunny dragon}; do
    [ "$name" = ico ] && [ ! -f ico8.ply ] &&
      python3 "$shared/bench/make_icosphere.py" --level 8 --out ico8.ply
    for kind in ${KINDS:-primary incoherent}; do
      rays=$name-$kind.rays
      [ -f "$rays" ] ||
        python3 "$shared/bench/make_rays.py" "${meshes[$name]}" --kind "$kind" --out "$rays"
      result=$("$plenum" bench --mesh "${meshes[$name]}" --rays "$rays" --accel bvh \
        --baseline embree --passes 7 --threads "${THREADS:-2}" --json)
      echo "{\"cell\":\"$name-$kind\",\"round\":$round,\"result\":$result}" >> "$out"
    done
  done
done
python3 - "$out" <<'PY'
import json, statistics, sys
cells = {}
for line in open(sys.argv[1]):
    run = json.loads(line)
    b = run["result"]["baseline"]
    cells.setdefault(run["cell"], []).append(
        (b["closest_speedup"]["median"], b["any_speedup"]["median"]))
print("BVH / Embree, in one process: mean (least-most) of each cell's runs")
for cell, runs in cells.items():
    closest, any_hit = [c for c, _ in runs], [a for _, a in runs]
    print(f"{cell:18} closest {statistics.mean(closest):.3f} "
          f"({min(closest):.2f}-{max(closest):.2f})  any {statistics.mean(any_hit):.3f} "
          f"({min(any_hit):.2f}-{max(any_hit):.2f})  [{len(runs)} runs]")
PY
