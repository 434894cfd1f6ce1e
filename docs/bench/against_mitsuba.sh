#!/usr/bin/env bash
# Plenum's path tracer against Mitsuba 3.9.1 on the Cornell box of
# shared/data/references/cbox/ (Mitsuba's `mi.cornell_box()`), 256x256, box filter,
# independent (uniform random) samples, 7 bounces, on THREADS threads (default 2).
#
#   docs/bench/against_mitsuba.sh [PLENUM] [WORK] [ROUNDS]
#   cargo build --release -p plenum-cli
#   docs/bench/against_mitsuba.sh target/release/plenum /tmp/against-mitsuba 5
#   QUALITY=0 MODES=rgb docs/bench/against_mitsuba.sh          # speed only, RGB only
#
# Speed: ROUNDS rounds (default 5), alternating within each: Plenum rgb, Mitsuba
# llvm_ad_rgb, Plenum spectral, Mitsuba llvm_ad_spectral, SPP (64) samples per pixel each.
# Plenum: the whole process (`plenum render ... --quiet`), wall and CPU time from bash's
# `time`. Mitsuba: the whole process (python start, import, scene, first render with the JIT
# kernel taken from Dr.Jit's disk cache after the first ever run, EXR write: mitsuba_cbox.py
# --rounds 0), and in a second process the steady render (median of STEADY_ROUNDS (3)
# renders after the first: no compilation). Prints medians, Mitsuba / Plenum per mode (above
# 1: Plenum is faster) and Plenum's spectral / rgb.
# Equal quality (QUALITY=1, the default): each renderer and mode at QUALITY_SPP (16 64 256)
# samples per pixel, one image each: whole-process time (and Mitsuba's steady render, from
# a second process) and RMSE against the reference of its mode (less the reference's own
# noise); then the time each needs for the RMSE Mitsuba reaches at 64 spp (the median over
# all its 64-spp images of the mode), from its point nearest that RMSE with
# RMSE ~ 1/sqrt(time), in wall and in CPU time. On a shared machine read the CPU columns:
# the wall times move with whatever else runs.
#
# Environment: MITSUBA_PY (default /work/venv-mitsuba/bin/python, with mitsuba==3.9.1;
# DRJIT_LIBLLVM_PATH defaults to Debian's libllvm19), SCENE (scenes/cornell-box.toml),
# PLENUM_MAX_DEPTH (6: Plenum counts bounces after the camera ray, so its 6 is Mitsuba's
# max_depth 8, the reference's 7 bounces), PLENUM_ARGS (default "--sampler random --filter
# box", the reference's conventions), THREADS, SPP, MODES ("rgb spectral"), STEADY_ROUNDS,
# QUALITY, QUALITY_SPP, MITSUBA_ONLY=1 (skip Plenum: the Mitsuba columns alone).
# Plenum's variance image, where it writes one beside its output as NAME-variance.exr, is
# given to the z-test. Raw results: WORK/against.jsonl; images: WORK/*.exr.
set -euo pipefail
if [ "${1:-}" = -h ] || [ "${1:-}" = --help ]; then
  sed -n '2,34p' "$0"
  exit 0
fi
here=$(dirname "$(realpath "$0")")
root=$(realpath "$here/../..")
refs=$(realpath "$here/../../../shared/data/references/cbox")
plenum=${1:-$root/target/release/plenum}
work=${2:-/tmp/against-mitsuba}
rounds=${3:-5}
py=${MITSUBA_PY:-/work/venv-mitsuba/bin/python}
scene=${SCENE:-$root/scenes/cornell-box.toml}
threads=${THREADS:-2} spp=${SPP:-64} modes=${MODES:-rgb spectral}
steady_rounds=${STEADY_ROUNDS:-3} quality=${QUALITY:-1} quality_spp=${QUALITY_SPP:-16 64 256}
plenum_depth=${PLENUM_MAX_DEPTH:-6}
read -r -a plenum_args <<< "${PLENUM_ARGS---sampler random --filter box}"
export DRJIT_LIBLLVM_PATH=${DRJIT_LIBLLVM_PATH:-/usr/lib/x86_64-linux-gnu/libLLVM-19.so}

fail() { echo "against_mitsuba.sh: $*" >&2; exit 2; }
if [ "${MITSUBA_ONLY:-0}" != 1 ]; then
  [ -x "$plenum" ] || fail "no Plenum binary at $plenum (build it: cargo build --release -p plenum-cli; or MITSUBA_ONLY=1 for the Mitsuba side alone)"
  plenum=$(realpath "$plenum")
  [ -f "$scene" ] || fail "no scene file $scene"
  "$plenum" render --help 2>/dev/null | grep -q -- '--integrator' ||
    fail "$plenum render has no --integrator option: a build without the path tracer?"
fi
[ -x "$py" ] || fail "no Python at $py (python3 -m venv /work/venv-mitsuba && /work/venv-mitsuba/bin/pip install mitsuba==3.9.1)"
"$py" -c 'import mitsuba' 2>/dev/null || fail "$py cannot import mitsuba"
[ -f "$DRJIT_LIBLLVM_PATH" ] || fail "no LLVM at $DRJIT_LIBLLVM_PATH (apt-get install -y libllvm19)"
[ -f "$refs/reference.exr" ] || fail "no reference in $refs"
mkdir -p "$work"
out=$work/against.jsonl
: > "$out"
variant() { echo "llvm_ad_$1"; }

# timed FILE CMD...: runs CMD (its stdout to FILE.out, stderr to FILE.err) and prints
# "wall user+sys" of the process and its children.
timed() {
  local f=$1; shift
  local TIMEFORMAT='%R %U %S' t
  t=$( { time "$@" > "$f.out" 2> "$f.err"; } 2>&1 ) || {
    echo "against_mitsuba.sh: failed: $*" >&2; cat "$f.err" >&2; return 1; }
  awk '{printf "%s %.3f\n", $1, $2 + $3}' <<< "$t"
}

plenum_run() {  # MODE SPP ROUND TAG
  local img=$work/plenum-$1-$2-$3.exr t w c
  t=$(timed "$work/plenum-$1-$2-$3" "$plenum" render "$scene" --integrator path \
    --color "$1" --spp "$2" --max-depth "$plenum_depth" "${plenum_args[@]}" --threads "$threads" \
    --quiet -o "$img")
  read -r w c <<< "$t"
  echo "{\"part\":\"$4\",\"renderer\":\"plenum\",\"mode\":\"$1\",\"spp\":$2,\"round\":$3,\"wall_s\":$w,\"cpu_s\":$c,\"image\":\"$img\",\"loadavg\":$(cut -d' ' -f1 /proc/loadavg)}" >> "$out"
}

mitsuba_run() {  # MODE SPP ROUND TAG STEADY_ROUNDS
  local img=$work/mitsuba-$1-$2-$3-$4.exr f=$work/mitsuba-$1-$2-$3-$4 t w c
  t=$(timed "$f" "$py" "$here/mitsuba_cbox.py" --variant "$(variant "$1")" --spp "$2" \
    --threads "$threads" --rounds "$5" --seed $((1000 * $3)) --out "$img" --quiet-summary --no-compare)
  read -r w c <<< "$t"
  echo "{\"part\":\"$4\",\"renderer\":\"mitsuba\",\"mode\":\"$1\",\"spp\":$2,\"round\":$3,\"rounds_in_process\":$5,\"wall_s\":$w,\"cpu_s\":$c,\"image\":\"$img\",\"loadavg\":$(cut -d' ' -f1 /proc/loadavg),\"summary\":$(tail -n 1 "$f.out")}" >> "$out"
}

for round in $(seq "$rounds"); do
  for mode in $modes; do
    [ "${MITSUBA_ONLY:-0}" = 1 ] || plenum_run "$mode" "$spp" "$round" speed
    mitsuba_run "$mode" "$spp" "$round" speed 0                  # the whole process
    mitsuba_run "$mode" "$spp" "$round" steady "$steady_rounds"  # steady renders
  done
  echo "round $round of $rounds done" >&2
done
if [ "$quality" = 1 ]; then
  for mode in $modes; do
    for s in $quality_spp; do
      [ "${MITSUBA_ONLY:-0}" = 1 ] || plenum_run "$mode" "$s" 0 quality
      mitsuba_run "$mode" "$s" 0 quality 0         # the whole process: its image and time
      mitsuba_run "$mode" "$s" 0 quality-steady 1  # the steady render's time
    done
  done
  echo "equal-quality renders done" >&2
fi

"$py" - "$out" "$refs" "$here" <<'PY'
import json, math, statistics, sys
out, refs, here = sys.argv[1:4]
sys.dont_write_bytecode = True  # no __pycache__ in docs/bench
sys.path.insert(0, here)
import os
import mitsuba_compare as mc

runs = [json.loads(l) for l in open(out)]
med = lambda xs: statistics.median(xs) if xs else float("nan")
refcache = {}
def reference(mode):
    if mode not in refcache:
        name = "reference-spectral" if mode == "spectral" else "reference"
        refcache[mode] = (mc.read_exr(f"{refs}/{name}.exr"), mc.read_exr(f"{refs}/{name}-variance.exr"))
    return refcache[mode]
def quality(run):
    ref, var = reference(run["mode"])
    img = mc.read_exr(run["image"])
    vpath = run["image"][:-4] + "-variance.exr"
    vimg = mc.read_exr(vpath) if os.path.exists(vpath) else None
    return mc.compare(img, ref, var, vimg)
for r in runs:
    if r["part"] in ("speed", "quality"):
        r["q"] = quality(r)

modes = [m for m in ("rgb", "spectral") if any(r["mode"] == m for r in runs)]
def pick(part, renderer, mode, spp=None):
    return [r for r in runs if r["part"] == part and r["renderer"] == renderer
            and r["mode"] == mode and (spp is None or r["spp"] == spp)]
speed = [r for r in runs if r["part"] == "speed"]
if speed:
    spp = speed[0]["spp"]
    nrounds = max(r["round"] for r in speed)
    print(f"\nSpeed: Cornell box 256x256, {spp} spp, {[r for r in runs if 'summary' in r][0]['summary']['threads']} threads; "
          f"medians of {nrounds} rounds; seconds, wall (CPU)")
    print(f"{'mode':9} {'Plenum':>15} {'Mitsuba whole':>15} {'in it: 1st render':>17} "
          f"{'Mitsuba steady':>15} {'M/P whole':>10} {'M steady/P':>10} {'(CPU)':>6}  Plenum mean/ref  Mitsuba mean/ref")
    pw, pc, mc_ = {}, {}, {}
    for mode in modes:
        p, m, st = pick("speed", "plenum", mode), pick("speed", "mitsuba", mode), pick("steady", "mitsuba", mode)
        pwall, pcpu = med([r["wall_s"] for r in p]), med([r["cpu_s"] for r in p])
        mwall, mcpu = med([r["wall_s"] for r in m]), med([r["cpu_s"] for r in m])
        first = med([r["summary"]["first_s"] for r in m])
        swall = med([r["summary"]["steady_median_s"] for r in st])
        scpu = med([r["summary"]["steady_cpu_median_s"] for r in st])
        pw[mode], pc[mode], mc_[mode] = pwall, pcpu, scpu
        f = lambda w, c: f"{w:7.3f} ({c:5.2f})" if w == w else f"{'-':>15}"
        meanrel = lambda rs: " ".join(f"{med([r['q']['mean_rel_diff_rgb'][i] for r in rs]):+.2%}" for i in range(3)) if rs else "-"
        print(f"{mode:9} {f(pwall, pcpu)} {f(mwall, mcpu)} {first:17.3f} {f(swall, scpu)} "
              f"{mwall / pwall:10.3f} {swall / pwall:10.3f} {scpu / pcpu:6.3f}  {meanrel(p):>15}  {meanrel(m)}")
    print("(M/P: Mitsuba's time / Plenum's whole process, wall; (CPU): Mitsuba's steady render / Plenum's whole process, CPU time)")
    if "rgb" in pw and "spectral" in pw and pw["rgb"] == pw["rgb"]:
        print(f"Plenum spectral / rgb: {pw['spectral'] / pw['rgb']:.3f} wall, {pc['spectral'] / pc['rgb']:.3f} CPU")
    ms = {mode: med([r["summary"]["steady_median_s"] for r in pick("steady", "mitsuba", mode)]) for mode in modes}
    if "rgb" in ms and "spectral" in ms:
        print(f"Mitsuba spectral / rgb (steady): {ms['spectral'] / ms['rgb']:.3f} wall, {mc_['spectral'] / mc_['rgb']:.3f} CPU")
    for mode in modes:
        for who in ("plenum", "mitsuba"):
            e = [r["q"]["rmse_less_ref_noise"] for r in pick("speed", who, mode)]
            if e:
                print(f"RMSE {who} {mode} {spp} spp: median {med(e):.5f} ({min(e):.5f}-{max(e):.5f}, {len(e)} images)")
    print(f"load average during the runs: {min(r['loadavg'] for r in runs):.2f}-{max(r['loadavg'] for r in runs):.2f}")
    for mode in modes:
        for who in ("plenum", "mitsuba"):
            rs = pick("speed", who, mode)
            if rs and "ztest" in rs[0]["q"]:
                z = rs[0]["q"]["ztest"]
                print(f"z-test {who} {mode} {spp} spp: {z['pass_fraction']:.4%} pass "
                      f"({z['variances']}{'; a noisy image fails by noise' if z['variances'] == 'reference only' else ''})")

qual = [r for r in runs if r["part"] == "quality"]
def steady_of(r):  # the steady render (wall, CPU) of a Mitsuba quality point
    st = [x for x in runs if x["part"] == "quality-steady" and x["mode"] == r["mode"] and x["spp"] == r["spp"]]
    return (st[0]["summary"]["steady_median_s"], st[0]["summary"]["steady_cpu_median_s"]) if st else (float("nan"),) * 2
if qual:
    print("\nEqual quality: RMSE against the reference of the mode (less the reference's noise); one image each")
    print(f"{'mode':9} {'renderer':8} {'spp':>5} {'wall s':>8} {'CPU s':>7} {'render s':>9} {'(CPU)':>7} {'RMSE':>9} {'rel.RMSE':>9}")
    for mode in modes:
        for r in sorted((r for r in qual if r["mode"] == mode), key=lambda r: (r["renderer"], r["spp"])):
            sw, sc = steady_of(r) if r["renderer"] == "mitsuba" else (float("nan"),) * 2
            print(f"{mode:9} {r['renderer']:8} {r['spp']:5} {r['wall_s']:8.3f} {r['cpu_s']:7.2f} "
                  f"{sw:9.3f} {sc:7.2f} {r['q']['rmse_less_ref_noise']:9.5f} {r['q']['rel_rmse']:9.3%}")
    def to_target(points, target):
        # points: (seconds, rmse, spp); the one nearest the target in log RMSE, RMSE ~ 1/sqrt(t)
        t, e, s = min(points, key=lambda p: abs(math.log(p[1] / target)))
        k = (e / target) ** 2
        return t * k, s * k, s
    for mode in modes:
        # the target: the median RMSE of all of Mitsuba's 64-spp images of the mode
        m64 = [r["q"]["rmse_less_ref_noise"] for r in runs if r.get("q") and r["mode"] == mode
               and r["renderer"] == "mitsuba" and r["spp"] == 64]
        if not m64:
            continue
        target = med(m64)
        print(f"{mode}: time to Mitsuba's 64-spp RMSE {target:.5f} (median of {len(m64)} images, "
              f"{min(m64):.5f}-{max(m64):.5f}); RMSE ~ 1/sqrt(time) from the nearest point; wall s (CPU s)")
        rows = {}
        for who, kind in (("plenum", "whole process"), ("mitsuba", "whole process"), ("mitsuba", "steady render")):
            rs = [r for r in qual if r["mode"] == mode and r["renderer"] == who]
            if not rs:
                continue
            res = []
            for i in (0, 1):  # wall, CPU
                pts = [((steady_of(r)[i] if kind == "steady render" else (r["wall_s"], r["cpu_s"])[i]),
                        r["q"]["rmse_less_ref_noise"], r["spp"]) for r in rs]
                res.append(to_target(pts, target))
            rows[f"{who} {kind}"] = (res[0][0], res[1][0])
            print(f"  {who + ' ' + kind:24} {res[0][0]:8.3f} s ({res[1][0]:.2f})  (~{res[0][1]:.0f} spp, from {res[0][2]} spp)")
        if "plenum whole process" in rows:
            p = rows["plenum whole process"]
            for k in ("mitsuba whole process", "mitsuba steady render"):
                print(f"  {k} / plenum whole process: {rows[k][0] / p[0]:.3f} wall, {rows[k][1] / p[1]:.3f} CPU")
PY
