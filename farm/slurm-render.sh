#!/usr/bin/env bash
# Renders one image on a Slurm cluster: a job array with one task per sample range
# (`plenum render --samples A..B`), then a merge job that runs once every task has succeeded
# (`--dependency=afterok`). The merged image is, byte for byte, the image of one render.
#
#   farm/slurm-render.sh [-p PARTS] [-d WORKDIR] [-b PLENUM] [-w] SCENE OUT SPP [RENDER OPTIONS...]
#
#   -p PARTS    tasks in the array (default 4); the SPP samples are split as evenly as can be
#   -d WORKDIR  where the parts and the jobs' logs go (default OUT's name + .parts), on a
#               file system every node sees
#   -b PLENUM   the plenum binary (default: `plenum` on the PATH)
#   -w          wait for the merge job to end, and exit with its status
#
# Prints the array's and the merge job's ids. Extra sbatch options go in SBATCH_* variables
# (SBATCH_PARTITION, SBATCH_TIMELIMIT, ...), which sbatch reads itself.
set -euo pipefail

parts=4 workdir="" plenum=plenum wait=""
while getopts "p:d:b:w" opt; do
    case $opt in
        p) parts=$OPTARG ;;
        d) workdir=$OPTARG ;;
        b) plenum=$OPTARG ;;
        w) wait=1 ;;
        *) exit 2 ;;
    esac
done
shift $((OPTIND - 1))
if [ $# -lt 3 ]; then
    echo "usage: $0 [-p PARTS] [-d WORKDIR] [-b PLENUM] [-w] SCENE OUT SPP [RENDER OPTIONS...]" >&2
    exit 2
fi
scene=$1 out=$2 spp=$3
shift 3
case $parts in ''|*[!0-9]*) echo "error: -p takes a whole number" >&2; exit 2 ;; esac
case $spp in ''|*[!0-9]*) echo "error: SPP must be a whole number" >&2; exit 2 ;; esac
if [ "$parts" -lt 1 ] || [ "$parts" -gt "$spp" ]; then
    echo "error: the parts must be between 1 and SPP ($spp)" >&2
    exit 2
fi
command -v sbatch > /dev/null || { echo "error: sbatch not found: is Slurm installed?" >&2; exit 2; }

abs() { case $1 in /*) printf '%s\n' "$1" ;; *) printf '%s/%s\n' "$PWD" "$1" ;; esac; }
scene=$(abs "$scene")
out=$(abs "$out")
workdir=$(abs "${workdir:-${out%.*}.parts}")
case $plenum in */*) plenum=$(abs "$plenum") ;; esac
mkdir -p "$workdir"

# Each task renders samples [i·spp/parts, (i+1)·spp/parts).
render_args=$(printf '%q ' "$@")
array=$(sbatch --parsable --array=0-$((parts - 1)) --job-name=plenum-part \
    --output="$workdir/part-%a.log" --chdir="$workdir" <<SCRIPT
#!/usr/bin/env bash
set -euo pipefail
i=\$SLURM_ARRAY_TASK_ID
a=\$(( i * $spp / $parts ))
b=\$(( (i + 1) * $spp / $parts ))
exec $(printf '%q' "$plenum") render $(printf '%q' "$scene") --spp $spp $render_args --quiet \\
    --samples "\$a..\$b" -o "part-\$i.plf"
SCRIPT
)
array=${array%%;*}
part_files=""
for ((i = 0; i < parts; i++)); do part_files+=" $(printf '%q' "$workdir/part-$i.plf")"; done
merge=$(sbatch --parsable --dependency=afterok:"$array" --job-name=plenum-merge \
    --output="$workdir/merge.log" --chdir="$workdir" <<SCRIPT
#!/usr/bin/env bash
set -euo pipefail
exec $(printf '%q' "$plenum") merge $part_files -o $(printf '%q' "$out")
SCRIPT
)
merge=${merge%%;*}
echo "array job $array ($parts parts), merge job $merge -> $out"

if [ -n "$wait" ]; then
    # Poll until the merge job has left the queue (or can never run: a part failed), then
    # tell by the image whether it succeeded (a cluster need not keep accounting).
    while reason=$(squeue -h -j "$merge" -o %r 2> /dev/null) && [ -n "$reason" ]; do
        if [ "$reason" = DependencyNeverSatisfied ]; then
            scancel "$merge"
            echo "error: a part failed, so the merge will not run; see $workdir/part-*.log" >&2
            exit 1
        fi
        sleep 1
    done
    if [ -s "$workdir/merge.log" ]; then cat "$workdir/merge.log" >&2; fi
    [ -f "$out" ] || { echo "error: the merge job did not write $out (see $workdir)" >&2; exit 1; }
fi
