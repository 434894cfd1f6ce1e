#!/usr/bin/env bash
# Plenum's Whitted ray tracer against POV-Ray 3.7 (Debian's `povray`) on the built-in scene
# (docs/bench/whitted.pov, 1024x768) and the 14 SPD scenes of ../shared/data/nff (at their
# files' resolutions, 512x512 but jacks' 256x256,
# written for POV-Ray by docs/bench/nff_to_pov.py), at 1 and 16 samples per pixel, both on
# every core (POV-Ray's default; Plenum's too), in turn, ROUNDS rounds (default 3).
#
#   cargo build --release -p plenum-cli
#   docs/bench/against_povray.sh [PLENUM] [WORK] [ROUNDS]
#   SCENES="builtin tree" SPPS=1 docs/bench/against_povray.sh
#
# Times are each program's own render time: POV-Ray's "Trace Time" (after parsing and
# bounding), Plenum's summary line (after loading and building its structures). 16 samples
# are POV-Ray's `+A0.0 +AM1 +R4` (every pixel supersampled 4x4, the same count as
# `--spp 16`); 1 sample is `-A`. The table: per scene and sample count the median over the
# rounds of each, and POV-Ray / Plenum (above 1: Plenum is faster).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
plenum=$(realpath "${1:-$here/../../target/release/plenum}")
work=${2:-/tmp/against-povray}
rounds=${3:-3}
nff=${NFF:-$here/../../../shared/data/nff}
scenes=${SCENES:-builtin balls3 balls4 gears jacks jacks4 lattice mount rings shells sombrero teapot teapot12 tetra tree}
spps=${SPPS:-1 16}
mkdir -p "$work"
command -v povray > /dev/null || { echo "povray not found (apt-get install povray)" >&2; exit 1; }

pov_of() {
    if [ "$1" = builtin ]; then
        echo "$here/whitted.pov"
    else
        python3 "$here/nff_to_pov.py" "$nff/$1.nff" > "$work/$1.pov"
        echo "$work/$1.pov"
    fi
}
# The NFF file's own resolution (written into the .pov by nff_to_pov.py).
size_of() {
    if [ "$1" = builtin ]; then echo "1024 768"; else sed -n 's|^// resolution ||p' "$work/$1.pov"; fi
}

povray_time() { # scene pov spp
    local w h aa
    read -r w h < <(size_of "$1")
    if [ "$3" = 1 ]; then aa="-A"; else aa="+A0.0 +AM1 +R4"; fi
    # shellcheck disable=SC2086
    (cd "$work" && povray -D +GA +W"$w" +H"$h" $aa +O"$work/$1-pov-$3.png" "$2" 2>&1) |
        sed -n 's/.*Trace Time:.*(\([0-9.]*\) seconds).*/\1/p'
}

plenum_time() { # scene spp
    local w h args=()
    read -r w h < <(size_of "$1")
    [ "$1" = builtin ] || args=("$nff/$1.nff")
    "$plenum" render "${args[@]}" --width "$w" --height "$h" --spp "$2" \
        -o "$work/$1-plenum-$2.png" 2>&1 | tail -1 | sed -n 's/.* spp, \([0-9.]*\) s,.*/\1/p'
}

median() { sort -g | awk '{a[NR]=$1} END {print (NR%2 ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2)}'; }

echo "plenum: $plenum ($(git -C "$here" rev-parse --short HEAD 2>/dev/null || echo '?'))"
echo "povray: $(povray --version 2>&1 | grep -m1 "^POV-Ray")"
echo "cpu: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | xargs), $(nproc) threads"
printf '%-9s %4s %12s %12s %8s\n' scene spp "povray s" "plenum s" ratio
for s in $scenes; do
    pov=$(pov_of "$s")
    for spp in $spps; do
        : > "$work/$s-$spp.pov.t"
        : > "$work/$s-$spp.plenum.t"
        for _ in $(seq "$rounds"); do
            povray_time "$s" "$pov" "$spp" >> "$work/$s-$spp.pov.t"
            plenum_time "$s" "$spp" >> "$work/$s-$spp.plenum.t"
        done
        a=$(median < "$work/$s-$spp.pov.t")
        b=$(median < "$work/$s-$spp.plenum.t")
        printf '%-9s %4s %12s %12s %8.2f\n' "$s" "$spp" "$a" "$b" "$(echo "$a / $b" | bc -l)"
    done
done
