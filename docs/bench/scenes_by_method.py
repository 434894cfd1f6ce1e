#!/usr/bin/env python3
"""Every scene, every physically based method: the table of docs/integrators.md.

    cargo build --release -p plenum-cli
    python3 docs/bench/scenes_by_method.py --plenum target/release/plenum --out /tmp/sbm

Each scene of scenes/ and the built-in one is rendered at 96×72 (random sampler, seed 1, the
scene's own colour mode and depth) by BDPT at 1024 spp, the reference, and by path (256 spp),
light (1024), photon (64) and sppm (256 iterations). For each method the table gives the
channel whose image mean is furthest from BDPT's, as a percentage, and the 12×12-pixel blocks
that BDPT lights (block mean above 0.01) but the method leaves below a fifth of BDPT's: the
regions a method cannot render at all. `--methods` and `--scenes` choose a part of the table.

Needs numpy (pip). Images are exchanged as PFM.
"""
import argparse
import os
import subprocess
import sys

import numpy as np

SPP = {"bdpt": 1024, "path": 256, "light": 1024, "photon": 64, "sppm": 256}
BLOCK = 12


def read_pfm(path):
    with open(path, "rb") as f:
        kind = f.readline().strip()
        width, height = map(int, f.readline().split())
        scale = float(f.readline())
        channels = 3 if kind == b"PF" else 1
        data = np.frombuffer(f.read(), dtype="<f4" if scale < 0 else ">f4")
    return data.reshape(height, width, channels)[::-1].astype(np.float64)


def render(plenum, scene, method, out):
    cmd = [plenum, "render"] + ([scene] if scene else []) + [
        "--integrator", method, "--spp", str(SPP[method]), "--sampler", "random",
        "--seed", "1", "--width", "96", "--height", "72", "--quiet", "-o", out,
    ]
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return read_pfm(out)


def blocks(image):
    h, w = image.shape[0] // BLOCK * BLOCK, image.shape[1] // BLOCK * BLOCK
    b = image[:h, :w].reshape(h // BLOCK, BLOCK, w // BLOCK, BLOCK, -1)
    return b.mean(axis=(1, 3, 4))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--plenum", default="target/release/plenum")
    ap.add_argument("--out", default="/tmp/scenes-by-method")
    ap.add_argument("--methods", default="path,light,photon,sppm")
    ap.add_argument("--scenes", default="", help="comma-separated names (default: all)")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    methods = args.methods.split(",")
    names = sorted(f[:-5] for f in os.listdir("scenes") if f.endswith(".toml"))
    scenes = [("(built-in)", None)] + [(n, f"scenes/{n}.toml") for n in names]
    if args.scenes:
        wanted = set(args.scenes.split(","))
        scenes = [s for s in scenes if s[0] in wanted]
    print("| scene | " + " | ".join(methods) + " |")
    print("|---|" + "---|" * len(methods))
    for name, path in scenes:
        stem = os.path.join(args.out, name.strip("()"))
        reference = render(args.plenum, path, "bdpt", f"{stem}.bdpt.pfm")
        ref_mean = reference.mean(axis=(0, 1))
        ref_blocks = blocks(reference)
        cells = []
        for method in methods:
            image = render(args.plenum, path, method, f"{stem}.{method}.pfm")
            rel = image.mean(axis=(0, 1)) / np.maximum(ref_mean, 1e-12) - 1.0
            worst = rel[np.argmax(np.abs(rel))]
            dark = int(np.sum((ref_blocks > 0.01) & (blocks(image) < 0.2 * ref_blocks)))
            cell = f"{100 * worst:+.1f} %"
            if dark:
                cell += f", {dark} dark blocks"
            cells.append(cell)
        print(f"| {name} | " + " | ".join(cells) + " |", flush=True)


if __name__ == "__main__":
    sys.exit(main())
