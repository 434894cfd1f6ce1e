#!/usr/bin/env bash
# The acceleration figures of docs/acceleration.md in one run: every structure (Embree
# included) on the bunny, the dragon and the level-8 icosphere, camera and incoherent rays,
# ROUNDS times over in turn, so that the machine's drift falls on all alike. Prints the
# table of medians, the ratios, and the BVH against Embree round by round (how far the
# machine moved); keeps the raw JSON lines in WORK/runs.jsonl.
#
#   docs/bench/one_run.sh PLENUM [WORK] [ROUNDS]
#   cargo build --release -p plenum-cli --features embree   # needs libembree-dev
#   docs/bench/one_run.sh target/release/plenum /tmp/one-run 5
#   THREADS=1 ACCELS="embree bvh" docs/bench/one_run.sh target/release/plenum  # one thread
# (ACCELS must name embree and bvh; THREADS is passed to `plenum bench --threads`.)
#
# Rays and the icosphere are made in WORK the first time (make_rays.py defaults: 1024²
# camera rays, 10⁶ incoherent rays); a round takes about a minute and a half on 2 cores.
set -euo pipefail
if [ $# -lt 1 ]; then
  sed -n '2,15p' "$0" >&2
  exit 2
fi
plenum=$(realpath "$1") work=${2:-/tmp/one-run} rounds=${3:-5}
accels=${ACCELS:-embree bvh grid octree}
threads=()
[ -n "${THREADS:-}" ] && threads=(--threads "$THREADS")
here=$(dirname "$(realpath "$0")")
shared=$(realpath "$here/../../../shared")
mkdir -p "$work"
cd "$work"
[ -f ico8.ply ] || python3 "$shared/bench/make_icosphere.py" --level 8 --out ico8.ply
declare -A meshes=(
  [bunny]="$shared/data/meshes/stanford-bunny.obj"
  [dragon]="$shared/data/meshes/dragon-100k.obj"
  [ico]="$work/ico8.ply"
)
for name in bunny dragon ico; do
  for kind in primary incoherent; do
    [ -f "$name-$kind.rays" ] ||
      python3 "$shared/bench/make_rays.py" "${meshes[$name]}" --kind $kind --out "$name-$kind.rays"
  done
done
: > runs.jsonl
for round in $(seq "$rounds"); do
  for name in bunny dragon ico; do
    for kind in primary incoherent; do
      for accel in $accels; do
        result=$("$plenum" bench --mesh "${meshes[$name]}" --rays "$name-$kind.rays" --accel $accel \
          "${threads[@]}" --json)
        echo "{\"round\":$round,\"mesh\":\"$name\",\"kind\":\"$kind\",\"result\":$result}" >> runs.jsonl
      done
    done
  done
done
python3 - runs.jsonl <<'EOF'
import json, statistics, sys
from collections import defaultdict
runs = defaultdict(list)
rounds = defaultdict(list)
for line in open(sys.argv[1]):
    row = json.loads(line)
    runs[row["mesh"], row["kind"], row["result"]["accel"]].append(row["result"])
    rounds[row["mesh"], row["kind"], row["result"]["accel"]].append(row["round"])
accels = [a for a in ["embree", "bvh", "grid", "octree"] if any(k[2] == a for k in runs)]
def median(mesh, kind, accel, field):
    return statistics.median(r[field] for r in runs[mesh, kind, accel])
print("| mesh | structure | camera rays | incoherent rays | build | bytes/triangle | closest vs Embree (camera / incoherent) |")
print("|---|---|---|---|---|---|---|")
for mesh in ["bunny", "dragon", "ico"]:
    for accel in accels:
        cells = [f"{median(mesh, k, accel, 'closest_mrays_per_s'):.1f} / "
                 f"{median(mesh, k, accel, 'any_mrays_per_s'):.1f}" for k in ["primary", "incoherent"]]
        both = runs[mesh, "primary", accel] + runs[mesh, "incoherent", accel]
        build = statistics.median(r["build_ms"] for r in both)
        size = "–" if accel == "embree" else f"{both[0]['bytes_per_primitive']:.1f}"
        ratio = [median(mesh, k, accel, "closest_mrays_per_s") / median(mesh, k, "embree", "closest_mrays_per_s")
                 for k in ["primary", "incoherent"]]
        print(f"| {mesh} | {accel} | {cells[0]} | {cells[1]} | {build:.0f} ms | {size} | {ratio[0]:.2f}× / {ratio[1]:.2f}× |")
print()
for mesh in ["bunny", "dragon", "ico"]:
    for kind in ["primary", "incoherent"]:
        bvh = [median(mesh, kind, "bvh", f) for f in ["closest_mrays_per_s", "any_mrays_per_s"]]
        ratios = []
        for other in [a for a in accels if a != "bvh"]:
            o = [median(mesh, kind, other, f) for f in ["closest_mrays_per_s", "any_mrays_per_s"]]
            ratios.append(f"bvh/{other} {bvh[0] / o[0]:.2f} {bvh[1] / o[1]:.2f}")
        print(f"{mesh} {kind} (closest, any): " + " | ".join(ratios))
# Embree and the BVH run one after the other in each round, so their ratio round by round
# shows how far the machine moved while the table was measured.
print()
by_round = defaultdict(dict)
for key, results in runs.items():
    for r, result in zip(rounds[key], results):
        by_round[key[0], key[1], r][key[2]] = result
for mesh in ["bunny", "dragon", "ico"]:
    for kind in ["primary", "incoherent"]:
        spread = []
        for field in ["closest_mrays_per_s", "any_mrays_per_s"]:
            ratios = sorted(by_round[mesh, kind, r]["bvh"][field] / by_round[mesh, kind, r]["embree"][field]
                            for r in sorted({r for (m, k, r) in by_round if (m, k) == (mesh, kind)}))
            spread.append(f"{statistics.median(ratios):.2f} ({ratios[0]:.2f}–{ratios[-1]:.2f})")
        print(f"{mesh} {kind} bvh/embree round by round, median (least–most): closest {spread[0]}, any {spread[1]}")
EOF
