#!/usr/bin/env python3
"""Plenum at the settings of the pbrt-v4 figures quoted in issue #33 (pbrt-v4 built on these
machines, a classic Cornell box at 256x256 with 8 bounces: `path` 64 spp 12.6 s, `bdpt`
32 spp 25.6 s, `sppm` 64 iterations 16.1 s), on scenes/cornell-box.toml (Mitsuba 3's box,
256x256, RGB), 2 threads, whole-process wall time.

pbrt-v4's `maxdepth` 8 is Plenum's `--max-depth 7` (Plenum counts bounces after the camera
ray; pbrt counts them with it). The RMSE is against ../shared/data/references/cbox's
converged Mitsuba render, which stops one bounce earlier (Mitsuba max_depth 8 = Plenum 6):
so each method is also run at --max-depth 6 for its error, at the same sample count.

    python3 docs/bench/pbrt_figures.py [--plenum target/release/plenum] [--rounds 1]

Needs numpy and OpenEXR (pip). Prints one JSON line per method.
"""
import argparse, json, os, subprocess, sys, tempfile, time

import numpy as np
import OpenEXR

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
REF = os.path.join(ROOT, "..", "shared", "data", "references", "cbox", "reference.exr")
PBRT_SECONDS = {"path": 12.6, "bdpt": 25.6, "sppm": 16.1}
SPP = {"path": 64, "bdpt": 32, "sppm": 64}


def read_exr(path):
    f = OpenEXR.File(path)
    channels = f.channels()
    if "RGB" in channels:
        return np.asarray(channels["RGB"].pixels, dtype=np.float64)
    return np.stack([np.asarray(channels[c].pixels, dtype=np.float64) for c in "RGB"], axis=-1)


def render(plenum, method, spp, depth, out):
    cmd = [plenum, "render", os.path.join(ROOT, "scenes", "cornell-box.toml"),
           "--integrator", method, "--spp", str(spp), "--max-depth", str(depth),
           "--color", "rgb", "--threads", "2", "-o", out]
    start = time.perf_counter()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return time.perf_counter() - start


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--plenum", default=os.path.join(ROOT, "target", "release", "plenum"))
    p.add_argument("--rounds", type=int, default=1)
    a = p.parse_args()
    reference = read_exr(REF)
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "image.exr")
        for method, spp in SPP.items():
            seconds = min(render(a.plenum, method, spp, 7, out) for _ in range(a.rounds))
            render(a.plenum, method, spp, 6, out)
            rmse = float(np.sqrt(np.mean((read_exr(out) - reference) ** 2)))
            print(json.dumps({
                "method": method, "spp": spp, "plenum_seconds": round(seconds, 2),
                "pbrt_seconds": PBRT_SECONDS[method],
                "pbrt_over_plenum": round(PBRT_SECONDS[method] / seconds, 2),
                "rmse_against_mitsuba_at_depth_6": round(rmse, 5),
            }), flush=True)


if __name__ == "__main__":
    sys.exit(main())
