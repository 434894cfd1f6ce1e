#!/bin/sh
# Seeds each target's corpus (fuzz/corpus/TARGET, not committed) from the shared data
# beside the repository and the example scenes: every file of the target's extension
# under 100 KB, the size a campaign's inputs may reach; and a small OBJ and MTL, which the
# shared data has only in larger files.
set -eu
cd "$(dirname "$0")"
data=${PLENUM_DATA:-../../shared/data}
for target in toml nff ray obj mtl ply xml gltf pbrt; do
    mkdir -p "corpus/$target"
    find "$data" ../scenes -name "*.$target" -size -100k 2>/dev/null |
        while read -r f; do
            cp "$f" "corpus/$target/$(basename "$(dirname "$f")")-$(basename "$f")"
        done
done
printf 'mtllib a.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\nusemtl red\nf 1/1/1 2/1/1 3/1/1\nf -3 -2 -1\n' > corpus/obj/triangle.obj
printf 'newmtl red\nKd 0.8 0.1 0.1\nKs 0.2 0.2 0.2\nNs 20\nd 1\nNi 1.5\nillum 2\n' > corpus/mtl/red.mtl
for target in toml nff ray obj mtl ply xml gltf pbrt; do
    echo "$target: $(ls "corpus/$target" | wc -l) seeds"
done
