#!/usr/bin/env bash
# Makes every picture and every printed ray tree of docs/tutorial.md, from the scenes in
# scenes/ and the built-in scene, with a release build. A teacher reruns it after changing
# a scene, or to make the lecture's figures at another size:
#
#   docs/tutorial.sh [PLENUM]    # default: builds and uses target/release/plenum
#   W=640 H=480 LADDER=320 OUT=figures docs/tutorial.sh
#
# It writes OUT (default docs/tutorial)/*.png, *.svg and *.txt; the times in
# acceleration.txt are this machine's. The pixels traced are given for 320 × 240 and
# scaled to the size asked.
set -euo pipefail
cd "$(dirname "$0")/.."
plenum=${1:-}
if [ -z "$plenum" ]; then
    cargo build --release --quiet
    plenum=target/release/plenum
fi
out=${OUT:-docs/tutorial}
mkdir -p "$out"
W=${W:-320}
H=${H:-240}
LADDER=${LADDER:-160}
small=(--width "$W" --height "$H")

# render SCENE PICTURE [options...]: one picture (and its views, with --aov) at the
# tutorial's size; the summary line goes to PICTURE.txt.
render() {
    local scene=$1 picture=$2
    shift 2
    echo "$scene -> $out/$picture.png" >&2
    "$plenum" render "$scene" "${small[@]}" -o "$out/$picture.png" "$@" 2> "$out/$picture.txt"
}
# tree SCENE X Y NAME [options...]: a pixel's ray tree as text and as a figure; (X, Y) in
# a 320 × 240 image.
tree() {
    local scene=$1 x=$(($2 * W / 320)) y=$(($3 * H / 240)) name=$4
    shift 4
    echo "$scene ($x, $y) -> $out/$name.txt, $out/$name.svg" >&2
    "$plenum" trace-pixel "$scene" "$x" "$y" "${small[@]}" --svg "$out/$name.svg" "$@" \
        > "$out/$name.txt"
}

# 1. The ray tree of a pixel on glass: the built-in scene's glass sphere.
render - builtin --spp 4
tree - 160 120 glass-tree --integrator whitted

# 2. Shadow rays: local illumination (no shadow rays), Appel's shadow rays, then Whitted.
for method in local appel whitted; do
    render scenes/shadows.toml "shadows-$method" --integrator "$method"
done
tree scenes/shadows.toml 110 150 shadow-tree --integrator whitted

# 3. Reflection and refraction, Snell's law and total internal reflection: the tree of a
# pixel on the lens-like sphere and one on the prism, whose back faces reflect totally.
render scenes/refraction.toml refraction
tree scenes/refraction.toml 70 150 snell-tree
tree scenes/refraction.toml 262 140 tir-tree

# 4. Fresnel: k_r and k_t from the Fresnel equations (left) against constants (right).
render scenes/fresnel.toml fresnel

# 5. Recursion depth: the corridor of two facing mirrors, bounce by bounce.
for depth in 0 1 2 5; do
    render scenes/recursion-depth.toml "depth-$depth" --max-depth "$depth" --aov depth
done

# 6. Aliasing and supersampling: the checkerboard to the horizon, one ray per pixel on a
# grid against sixteen jittered ones.
render scenes/checkerboard-horizon.toml aliasing-1 --sampler grid --spp 1
render scenes/checkerboard-horizon.toml aliasing-16 --sampler jittered --spp 16

# 7. Adaptive sampling: Whitted's corner subdivision, and sampling until the noise is low,
# with the samples each pixel took.
render scenes/checkerboard-horizon.toml adaptive-subdivide --sampler adaptive --aov rays
render scenes/soft-shadows.toml adaptive-variance --sampler adaptive --noise-threshold 0.05 --min-spp 8 \
    --spp 256 --aov spp

# 8. The distribution effects: soft shadows, glossy reflection, depth of field, motion blur.
for scene in soft-shadows glossy depth-of-field motion-blur; do
    render "scenes/$scene.toml" "$scene"
done

# 9. Acceleration: a field of 1,089 spheres (written here), rendered with each structure;
# the cost view shows the node visits and tests per pixel, the summary line the time.
field=$(mktemp --suffix=.toml)
{
    cat << 'EOF'
# A field of spheres on a floor, for comparing acceleration structures.
background = [0.55, 0.65, 0.8]
[render]
spp = 1
max_depth = 2
[camera]
position = [0.0, 6.0, 16.0]
look_at = [0.0, 0.0, -4.0]
up = [0.0, 1.0, 0.0]
fov = 50
[[lights]]
type = "point"
position = [10.0, 20.0, 10.0]
color = [1.0, 1.0, 1.0]
[materials.floor]
diffuse = 0.6
ambient = 0.1
[materials.ball]
diffuse = [0.8, 0.3, 0.2]
specular = 0.4
shininess = 40
ambient = 0.1
[[objects]]
type = "plane"
point = [0.0, 0.0, 0.0]
normal = [0.0, 1.0, 0.0]
material = "floor"
EOF
    awk 'BEGIN {
        for (i = 0; i < 33; i++) for (j = 0; j < 33; j++) {
            r = 0.12 + 0.1 * ((i * 7 + j * 13) % 5) / 4;
            printf "[[objects]]\ntype = \"sphere\"\ncenter = [%.3f, %.3f, %.3f]\nradius = %.3f\nmaterial = \"ball\"\n",
                (i - 16) * 0.6, r, -(j * 0.6) + 6, r
        }
    }'
} > "$field"
: > "$out/acceleration.txt"
views=$(mktemp -d)
trap 'rm -rf "$field" "$views"' EXIT
for accel in bvh grid octree none; do
    echo "$field --accel $accel -> $out/accel-$accel.cost.png" >&2
    # One scale for the four cost views: white is 800 node visits and tests or more.
    "$plenum" render "$field" "${small[@]}" --spp 4 --accel "$accel" --aov cost --aov-max 800 \
        -o "$views/accel-$accel.png" 2>&1 | sed -e "s|$field|field-of-spheres.toml|" \
        -e "s|$views/|docs/tutorial/|g" >> "$out/acceleration.txt"
    mv "$views/accel-$accel.cost.png" "$out/"
done
mv "$views/accel-bvh.png" "$out/accel-field.png"

# 10. The ladder, from local illumination to bidirectional path tracing, on one scene.
for method in local appel whitted path light photon sppm bdpt; do
    render scenes/ladder.toml "ladder-$method" --integrator "$method" --width "$LADDER" --height "$LADDER"
done
