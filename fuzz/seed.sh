#!/bin/sh
# Seeds each target's corpus (fuzz/corpus/TARGET, not committed) from the shared data
# beside the repository and the example scenes: every file of the target's extension
# under 100 KB, the size a campaign's inputs may reach.
set -eu
cd "$(dirname "$0")"
data=${PLENUM_DATA:-../../shared/data}
for target in toml nff ray obj mtl ply; do
    mkdir -p "corpus/$target"
    find "$data" ../scenes -name "*.$target" -size -100k 2>/dev/null |
        while read -r f; do cp "$f" "corpus/$target/$(echo "$f" | tr '/' '_')"; done
    echo "$target: $(ls "corpus/$target" | wc -l) seeds"
done
