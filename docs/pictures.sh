#!/usr/bin/env bash
# Renders the pictures in docs/ from the scenes in scenes/, each at the scene's own settings,
# with a release build: run it after any change that changes images, and commit the result.
# (docs/ladder-grid.png and docs/ladder-rmse.png are measurements: docs/bench/ladder.py.)
#
#   docs/pictures.sh [PLENUM]    # default: builds and uses target/release/plenum
set -euo pipefail
cd "$(dirname "$0")/.."
plenum=${1:-}
if [ -z "$plenum" ]; then
    cargo build --release --quiet
    plenum=target/release/plenum
fi
render() { # scene picture [options...]
    local scene=$1 picture=$2
    shift 2
    echo "scenes/$scene.toml -> docs/$picture.png" >&2
    "$plenum" render "scenes/$scene.toml" --quiet -o "docs/$picture.png" "$@"
}
render whitted whitted
render cornell-box cornell-box
render glass glass
render metals metals
render rough-metals rough-metals
render prism prism

# The page of `plenum view` (README), with the ray tree of the glass sphere's middle pixel,
# by headless Chromium (Debian: chromium).
log=$(mktemp)
"$plenum" view --width 320 --height 240 --spp 16 > "$log" &
view=$!
trap 'kill $view 2> /dev/null; rm -f "$log"' EXIT
until grep -q http "$log"; do sleep 0.1; done
address=$(grep -o 'http://[^ ]*' "$log")
echo "plenum view -> docs/view.png" >&2
chromium --headless --no-sandbox --disable-gpu --disable-dev-shm-usage --hide-scrollbars \
    --window-size=1280,760 --virtual-time-budget=20000 \
    --screenshot="$PWD/docs/view.png" "${address}#trace=160,120" 2> /dev/null
