#!/usr/bin/env python3
"""One scene, every method: render a scene with every integrator of Plenum's ladder at a
series of sample counts, measure each render's whole-process wall time and its RMSE against a
long reference render, and draw the figures of docs/integrators.md.

    cargo build --release -p plenum-cli
    python3 docs/bench/ladder.py --plenum target/release/plenum --scene scenes/ladder.toml \
        --out /tmp/ladder --budget 4

What it does, in one run on THREADS threads (default 2):
  1. a reference: `--reference-integrator` (bdpt) at `--reference-spp` (2048) samples per
     pixel, or the file given by `--reference`;
  2. for each integrator, renders at 1, 2, 4, ... samples per pixel (SPPM: iterations) until
     one render takes longer than 2 × BUDGET seconds, recording wall time and RMSE (linear
     radiance, over all pixels and channels, and over the pixels that see no emitter: see
     `off_emitters`); the reference has another seed than the renders;
  3. per integrator, the render whose time is nearest BUDGET goes into a grid of pictures
     (OUT/grid.png, each labelled with its time and RMSE), and every point into a log-log plot
     of RMSE against time (OUT/rmse-time.png); the table is printed and written to
     OUT/ladder.json.
Local illumination, Appel and Whitted do not converge to the physically based image (no
indirect light, Phong's reading of the materials): their RMSE is their bias.

Needs numpy, Pillow and matplotlib (pip). Images are exchanged as PFM.
"""
import argparse
import json
import os
import subprocess
import sys
import time

import numpy as np

LADDER = ["local", "appel", "whitted", "path", "light", "photon", "sppm", "bdpt"]


def read_pfm(path):
    with open(path, "rb") as f:
        kind = f.readline().strip()
        if kind != b"PF":
            raise ValueError(f"{path}: not an RGB PFM")
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        data = np.frombuffer(f.read(), dtype="<f4" if scale < 0 else ">f4")
    return data.reshape(h, w, 3)[::-1].astype(np.float64)


def off_emitters(ref, threshold):
    """The pixels that do not see an emitter: those whose reference is below `threshold` in
    every channel and whose neighbours are too. A lamp's edge pixels, half lamp and half
    wall, carry a noise that depends only on how many camera samples a method spends per
    pixel; left in, they hide the difference the methods make everywhere else."""
    hot = ref.max(axis=2) > threshold
    grown = hot.copy()
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            grown |= np.roll(np.roll(hot, dy, 0), dx, 1)
    return ~grown


def render(args, integrator, spp, out, seed=1):
    cmd = [
        args.plenum, "render", args.scene, "--integrator", integrator, "--spp", str(spp),
        "--width", str(args.size), "--height", str(args.size), "--color", args.color,
        "--threads", str(args.threads), "--seed", str(seed), "-q", "-o", out,
    ] + args.extra
    start = time.perf_counter()
    subprocess.run(cmd, check=True)
    return time.perf_counter() - start


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--plenum", default="target/release/plenum")
    p.add_argument("--scene", default="scenes/ladder.toml")
    p.add_argument("--out", default="/tmp/ladder")
    p.add_argument("--size", type=int, default=128, help="image width and height")
    p.add_argument("--budget", type=float, default=4.0, help="seconds per picture of the grid")
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--color", default="rgb", choices=["rgb", "spectral"])
    p.add_argument("--integrators", default=",".join(LADDER))
    p.add_argument("--reference", help="a PFM to compare with, instead of rendering one")
    p.add_argument("--reference-integrator", default="bdpt")
    p.add_argument("--reference-spp", type=int, default=2048)
    p.add_argument("--max-spp", type=int, default=4096)
    p.add_argument("--reuse", help="an earlier run's ladder.json: its renders and times, errors measured again")
    p.add_argument("--emitter-threshold", type=float, default=10.0,
                   help="reference radiance above which a pixel counts as seeing an emitter")
    p.add_argument("extra", nargs="*", help="more arguments for plenum render (after --)")
    args = p.parse_args()
    os.makedirs(args.out, exist_ok=True)

    ref_path = args.reference or os.path.join(args.out, "reference.pfm")
    if not args.reference:
        # Another seed than the renders', so that their first samples are not the reference's.
        t = render(args, args.reference_integrator, args.reference_spp, ref_path, seed=1000001)
        print(f"reference: {args.reference_integrator} at {args.reference_spp} spp, {t:.1f} s", file=sys.stderr)
    ref = read_pfm(ref_path)
    keep = off_emitters(ref, args.emitter_threshold)

    results = {}
    if args.reuse:
        # The renders and times of an earlier run, measured again against this reference.
        with open(args.reuse) as f:
            results = json.load(f)["results"]
        for points in results.values():
            for q in points:
                err = (read_pfm(q["file"]) - ref) ** 2
                q["rmse"] = float(np.sqrt(np.mean(err)))
                q["rmse_off_emitters"] = float(np.sqrt(np.mean(err[keep])))
    for integrator in [] if args.reuse else args.integrators.split(","):
        points = []
        spp = 1
        while spp <= args.max_spp:
            out = os.path.join(args.out, f"{integrator}-{spp}.pfm")
            t = render(args, integrator, spp, out)
            err = (read_pfm(out) - ref) ** 2
            rmse = float(np.sqrt(np.mean(err)))
            rmse_off = float(np.sqrt(np.mean(err[keep])))
            points.append({"spp": spp, "seconds": t, "rmse": rmse, "rmse_off_emitters": rmse_off, "file": out})
            print(f"{integrator:8} {spp:5} spp {t:7.2f} s  RMSE {rmse:.5f}  off emitters {rmse_off:.5f}", file=sys.stderr)
            if t > 2 * args.budget:
                break
            spp *= 2
        results[integrator] = points
    with open(os.path.join(args.out, "ladder.json"), "w") as f:
        json.dump({"scene": args.scene, "size": args.size, "threads": args.threads,
                   "color": args.color, "budget": args.budget, "results": results}, f, indent=1)

    # At the budget: each method's point nearest it in time, and its RMSE there by
    # RMSE ∝ 1/√time from that point (for the converging methods).
    print(f"\nat {args.budget:g} s ({args.size}×{args.size}, {args.threads} threads, {args.color}):")
    print(f"{'method':8} {'spp':>6} {'time s':>8} {'RMSE':>9} {'off emitters':>13} {'(at budget)':>12}")
    picks = {}
    for name, points in results.items():
        best = min(points, key=lambda q: abs(np.log(q["seconds"] / args.budget)))
        picks[name] = best
        at_budget = best["rmse_off_emitters"] * np.sqrt(best["seconds"] / args.budget)
        print(f"{name:8} {best['spp']:6} {best['seconds']:8.2f} {best['rmse']:9.5f} "
              f"{best['rmse_off_emitters']:13.5f} {at_budget:12.5f}")

    from PIL import Image, ImageDraw
    tiles = []
    for name, q in picks.items():
        im = read_pfm(q["file"])
        srgb = np.where(im <= 0.0031308, 12.92 * im, 1.055 * np.power(np.clip(im, 0, None), 1 / 2.4) - 0.055)
        tile = Image.fromarray((np.clip(srgb, 0, 1) * 255 + 0.5).astype(np.uint8))
        canvas = Image.new("RGB", (tile.width, tile.height + 30), "white")
        canvas.paste(tile, (0, 0))
        d = ImageDraw.Draw(canvas)
        d.text((3, tile.height + 2), f"{name}: {q['spp']} spp", fill="black")
        d.text((3, tile.height + 15), f"{q['seconds']:.1f} s, RMSE {q['rmse']:.4f}", fill="black")
        tiles.append(canvas)
    cols = 4
    rows = (len(tiles) + cols - 1) // cols
    grid = Image.new("RGB", (cols * tiles[0].width, rows * tiles[0].height), "white")
    for i, t in enumerate(tiles):
        grid.paste(t, ((i % cols) * t.width, (i // cols) * t.height))
    grid.save(os.path.join(args.out, "grid.png"))

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 4), dpi=110)
    for name, points in results.items():
        ax.loglog([q["seconds"] for q in points], [q["rmse_off_emitters"] for q in points], "o-", label=name, markersize=3)
    ax.set_xlabel("whole-process wall time (s)")
    ax.set_ylabel("RMSE against the reference, off emitters")
    ax.set_title(f"{os.path.basename(args.scene)}, {args.size}×{args.size}, {args.threads} threads, {args.color}")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(os.path.join(args.out, "rmse-time.png"))


if __name__ == "__main__":
    main()
