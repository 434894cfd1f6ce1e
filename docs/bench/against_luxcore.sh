#!/usr/bin/env bash
# Plenum's bidirectional path tracer (and its path tracer, as Plenum's own baseline) against
# LuxCore 2.11.2's BIDIRCPU on the Cornell box of shared/data/references/cbox/ (Mitsuba's
# `mi.cornell_box()`), 256x256, one-pixel box pixels, uniform random samples, RGB, on THREADS
# threads (default 2), at equal time: the RMSE against reference.exr.
#
#   docs/bench/against_luxcore.sh [PLENUM] [WORK] [ROUNDS]
#   cargo build --release -p plenum-cli
#   docs/bench/against_luxcore.sh target/release/plenum /tmp/against-luxcore 2
#   BUDGETS="2 4" ROUNDS=1 docs/bench/against_luxcore.sh /tmp/plenum-bin/plenum
#
# For each time budget in BUDGETS (seconds, default "2 4 8 16") and each of ROUNDS rounds
# (default 2), alternating: LuxCore renders for the budget (docs/bench/luxcore_cbox.py
# --seconds B: batch.halttime; the whole process, python start, import, scene, render and
# image write, timed by bash), then Plenum `--integrator bdpt` and `--integrator path`, each
# with the sample count that makes its whole process (`plenum render ... --quiet`) last about
# as long as that LuxCore process did: Plenum's seconds per sample per pixel are measured first
# with CAL_SPP (4) samples per pixel (one process per integrator, its time less the process's
# start-up, measured at 1 spp, taken as linear in spp), and re-estimated after every run from
# that run. Every image is written as PFM (Plenum's `-o x.pfm`; LuxCore's by numpy) and
# compared with reference.exr (read with the `openexr` pip package in LuxCore's venv): RMSE
# over all pixels and channels, as mitsuba_compare.py's "rmse" (no correction for the
# reference's own noise, which is ~0.0016 there, far below these).
# The table: per budget and renderer the medians over the rounds of wall time, spp and RMSE;
# "RMSE @T" is each RMSE scaled to LuxCore's wall time T of that budget by RMSE ~ 1/sqrt(time)
# (the small time mismatch taken out); "vs LuxCore" is Plenum's RMSE @T / LuxCore's (below 1:
# Plenum is less noisy at equal time); "time for equal RMSE" is (RMSE ratio)^2, the time
# Plenum needs for LuxCore's RMSE over LuxCore's time (below 1: Plenum is faster).
#
# LuxCore's image is not the reference's (see luxcore_cbox.py's header): its PATHCPU render of
# the same scene file matches the reference's mean to 0.05 %, but BIDIRCPU with path.maxdepth 8
# and light.maxdepth 7 (the smallest with every strategy of every path up to the reference's
# 7 bounces) comes out 12 % (red), 5 % (green), 3 % (blue) brighter, too bright everywhere
# but on the light (+10-50 % per region, with 1 thread or 2, RANDOM or SOBOL): far more than
# the light beyond 7 bounces (+1.8 % red in PATHCPU at depth 16). So LuxCore's RMSE here has a
# bias floor of about 0.03 that does not fall with time; the table reports it as it is.
#
# Environment: LUXCORE_PY (default /work/venv-luxcore/bin/python, with pyluxcore==2.11.2,
# numpy and openexr), SCENE (scenes/cornell-box.toml), PLENUM_MAX_DEPTH (6: Plenum counts
# bounces after the camera ray, the reference's 7 bounces), PLENUM_ARGS (default "--sampler
# random --filter box --color rgb"), THREADS, BUDGETS, CAL_SPP, INTEGRATORS ("bdpt path").
# Raw results: WORK/against.jsonl; images: WORK/*.pfm.
set -euo pipefail
shopt -s inherit_errexit  # a failed render inside $(...) stops the script
if [ "${1:-}" = -h ] || [ "${1:-}" = --help ]; then
  sed -n '2,46p' "$0"
  exit 0
fi
here=$(dirname "$(realpath "$0")")
root=$(realpath "$here/../..")
refs=$(realpath "$here/../../../shared/data/references/cbox")
plenum=${1:-$root/target/release/plenum}
work=${2:-/tmp/against-luxcore}
rounds=${3:-${ROUNDS:-2}}
py=${LUXCORE_PY:-/work/venv-luxcore/bin/python}
scene=${SCENE:-$root/scenes/cornell-box.toml}
threads=${THREADS:-2} budgets=${BUDGETS:-2 4 8 16} cal_spp=${CAL_SPP:-4}
integrators=${INTEGRATORS:-bdpt path}
plenum_depth=${PLENUM_MAX_DEPTH:-6}
read -r -a plenum_args <<< "${PLENUM_ARGS---sampler random --filter box --color rgb}"

fail() { echo "against_luxcore.sh: $*" >&2; exit 2; }
[ -x "$plenum" ] || fail "no Plenum binary at $plenum (build it: cargo build --release -p plenum-cli)"
plenum=$(realpath "$plenum")
[ -f "$scene" ] || fail "no scene file $scene"
"$plenum" render --help 2>/dev/null | grep -q -- 'bdpt' ||
  fail "$plenum render has no bdpt integrator"
[ -x "$py" ] || fail "no Python at $py (python3 -m venv /work/venv-luxcore && /work/venv-luxcore/bin/pip install pyluxcore==2.11.2 numpy openexr)"
"$py" -c 'import OpenEXR, pyluxcore' > /dev/null 2>&1 || fail "$py cannot import pyluxcore and OpenEXR"
[ -f "$refs/reference.exr" ] || fail "no reference in $refs"
mkdir -p "$work"
out=$work/against.jsonl
: > "$out"

# timed FILE CMD...: runs CMD (stdout to FILE.out, stderr to FILE.err), prints "wall user+sys"
timed() {
  local f=$1; shift
  local TIMEFORMAT='%R %U %S' t
  t=$( { time "$@" > "$f.out" 2> "$f.err"; } 2>&1 ) || {
    echo "against_luxcore.sh: failed: $*" >&2; cat "$f.err" >&2; return 1; }
  awk '{printf "%s %.3f\n", $1, $2 + $3}' <<< "$t"
}

plenum_run() {  # INTEGRATOR SPP TAG BUDGET ROUND -> prints the wall time
  local f=$work/plenum-$1-$3-b$4-r$5 t w c
  t=$(timed "$f" "$plenum" render "$scene" --integrator "$1" --spp "$2" \
    --max-depth "$plenum_depth" "${plenum_args[@]}" --threads "$threads" --seed "$5" --quiet -o "$f.pfm")
  read -r w c <<< "$t"
  echo "{\"part\":\"$3\",\"renderer\":\"plenum-$1\",\"budget\":$4,\"round\":$5,\"spp\":$2,\"wall_s\":$w,\"cpu_s\":$c,\"image\":\"$f.pfm\",\"loadavg\":$(cut -d' ' -f1 /proc/loadavg)}" >> "$out"
  echo "$w"
}

luxcore_run() {  # BUDGET ROUND -> prints the wall time
  local f=$work/luxcore-b$1-r$2 t w c
  t=$(timed "$f" "$py" "$here/luxcore_cbox.py" --seconds "$1" --threads "$threads" --seed "$2" --out "$f.pfm")
  read -r w c <<< "$t"
  echo "{\"part\":\"run\",\"renderer\":\"luxcore\",\"budget\":$1,\"round\":$2,\"wall_s\":$w,\"cpu_s\":$c,\"image\":\"$f.pfm\",\"loadavg\":$(cut -d' ' -f1 /proc/loadavg),\"summary\":$(tail -n 1 "$f.out")}" >> "$out"
  echo "$w"
}

if ps -eo comm | grep -qE '^(cargo|rustc)$'; then
  echo "against_luxcore.sh: cargo/rustc is running: the times are noisy" >&2
fi
# Plenum's start-up (1 spp) and its seconds per spp per integrator
declare -A per_spp
for integ in $integrators; do
  w1=$(plenum_run "$integ" 1 cal 0 1)
  wc=$(plenum_run "$integ" "$cal_spp" cal 0 2)
  per_spp[$integ]=$(awk -v a="$w1" -v b="$wc" -v n="$cal_spp" 'BEGIN { d = (b - a) / (n - 1); if (d <= 0) d = b / n; print d }')
  startup=$(awk -v a="$w1" -v d="${per_spp[$integ]}" 'BEGIN { s = a - d; print (s > 0 ? s : 0) }')
  declare "startup_$integ=$startup"
  echo "plenum $integ: ${per_spp[$integ]} s per spp, start-up $startup s" >&2
done
for round in $(seq "$rounds"); do
  for b in $budgets; do
    lw=$(luxcore_run "$b" "$round")
    for integ in $integrators; do
      s0=startup_$integ
      spp=$(awk -v t="$lw" -v s="${!s0}" -v d="${per_spp[$integ]}" 'BEGIN { n = int((t - s) / d + 0.5); print (n < 1 ? 1 : n) }')
      pw=$(plenum_run "$integ" "$spp" run "$b" "$round")
      # re-estimate seconds per spp from this run
      per_spp[$integ]=$(awk -v w="$pw" -v s="${!s0}" -v n="$spp" -v d="${per_spp[$integ]}" 'BEGIN { x = (w - s) / n; print (x > 0 ? x : d) }')
    done
    echo "round $round of $rounds, budget $b s done (LuxCore $lw s)" >&2
  done
done

"$py" - "$out" "$refs" "$here" <<'PY'
import json, math, statistics, sys
out, refs, here = sys.argv[1:4]
sys.dont_write_bytecode = True
sys.path.insert(0, here)
import luxcore_cbox as lc  # its readers only (no pyluxcore import)
import numpy as np
ref = lc.read_exr(f"{refs}/reference.exr")
runs = [json.loads(l) for l in open(out)]
runs = [r for r in runs if r["part"] == "run"]
for r in runs:
    d = lc.read_pfm(r["image"]) - ref
    r["rmse"] = float(np.sqrt((d * d).mean()))
    r["mean_rel"] = (lc.read_pfm(r["image"]).reshape(-1, 3).mean(0) / ref.reshape(-1, 3).mean(0) - 1).tolist()
    if r["renderer"] == "luxcore":
        r["spp"] = r["summary"]["spp"]
med = statistics.median
renderers = ["luxcore"] + sorted({r["renderer"] for r in runs} - {"luxcore"})
budgets = sorted({r["budget"] for r in runs})
nrounds = max(r["round"] for r in runs)
print(f"\nCornell box 256x256, RGB, 7 bounces, uniform random samples; medians of {nrounds} round(s); "
      f"whole-process wall seconds; RMSE against reference.exr over all pixels and channels")
print(f"{'budget':>6} {'renderer':13} {'wall s':>7} {'CPU s':>7} {'spp':>8} {'RMSE':>8} {'RMSE @T':>8} "
      f"{'vs LuxCore':>10} {'time for equal RMSE':>19}  mean vs reference (R G B)")
for b in budgets:
    lux = [r for r in runs if r["budget"] == b and r["renderer"] == "luxcore"]
    T = med([r["wall_s"] for r in lux])
    lux_at = med([r["rmse"] for r in lux]) * math.sqrt(med([r["wall_s"] for r in lux]) / T)
    for who in renderers:
        rs = [r for r in runs if r["budget"] == b and r["renderer"] == who]
        if not rs:
            continue
        w, c = med([r["wall_s"] for r in rs]), med([r["cpu_s"] for r in rs])
        e = med([r["rmse"] for r in rs])
        e_at = med([r["rmse"] * math.sqrt(r["wall_s"] / T) for r in rs])
        ratio = e_at / lux_at
        mr = " ".join(f"{med([r['mean_rel'][i] for r in rs]):+.2%}" for i in range(3))
        vs = "" if who == "luxcore" else f"{ratio:10.3f}"
        tt = "" if who == "luxcore" else f"{ratio ** 2:19.3f}"
        print(f"{b:6g} {who:13} {w:7.2f} {c:7.2f} {med([r['spp'] for r in rs]):8.1f} {e:8.5f} {e_at:8.5f} "
              f"{vs:>10} {tt:>19}  {mr}")
print(f"load average during the runs: {min(r['loadavg'] for r in runs):.2f}-{max(r['loadavg'] for r in runs):.2f}")
print("(RMSE @T: scaled to LuxCore's median wall time T of the budget by RMSE ~ 1/sqrt(time); "
      "vs LuxCore: Plenum's RMSE @T / LuxCore's; time for equal RMSE: its square, Plenum's time "
      "for LuxCore's RMSE / LuxCore's time, by RMSE ~ 1/sqrt(time) — LuxCore's own RMSE includes "
      "its bias, see the header)")
PY
