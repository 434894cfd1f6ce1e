#!/usr/bin/env python3
"""Renders one image over a Dask cluster: one task per sample range (`plenum render
--samples A..B`), then `plenum merge` of the parts. The merged image is, byte for byte, the
image of one render.

    farm/dask_render.py SCENE OUT SPP [--parts P] [--workers N | --scheduler ADDRESS]
                        [--plenum BIN] [--workdir DIR] [-- RENDER OPTIONS...]

Without --scheduler it starts a local cluster of N worker processes (one thread each; give
each render `--threads` to match the cores it should use). With --scheduler it sends the
tasks to a running cluster, whose workers must see the scene and the work folder.
"""

import argparse
import os
import subprocess
import sys
import time


def render_part(plenum, scene, spp, a, b, path, options):
    """One task: samples a..b of every pixel, into the film file `path`."""
    command = [plenum, "render", scene, "--spp", str(spp), *options, "--quiet",
               "--samples", f"{a}..{b}", "-o", path]
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"samples {a}..{b} failed ({done.returncode}): {done.stderr.strip()}")
    return path


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("scene")
    parser.add_argument("out")
    parser.add_argument("spp", type=int)
    parser.add_argument("--parts", type=int, default=4)
    parser.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--scheduler", help="address of a running Dask scheduler")
    parser.add_argument("--plenum", default="plenum", help="the plenum binary")
    parser.add_argument("--workdir", help="where the parts go (default: OUT's name + .parts)")
    argv = sys.argv[1:]
    split = argv.index("--") if "--" in argv else len(argv)
    args = parser.parse_args(argv[:split])
    options = argv[split + 1:]  # after --: options for every `plenum render`
    if not 1 <= args.parts <= args.spp:
        parser.error(f"--parts must be between 1 and SPP ({args.spp})")

    from dask.distributed import Client, LocalCluster

    absolute = os.path.abspath
    plenum = absolute(args.plenum) if os.sep in args.plenum else args.plenum
    scene, out = absolute(args.scene), absolute(args.out)
    workdir = absolute(args.workdir or os.path.splitext(out)[0] + ".parts")
    os.makedirs(workdir, exist_ok=True)

    start = time.perf_counter()
    if args.scheduler:
        client, cluster = Client(args.scheduler), None
    else:
        cluster = LocalCluster(n_workers=args.workers, threads_per_worker=1,
                               processes=True, dashboard_address=None)
        client = Client(cluster)
    try:
        ranges = [(i * args.spp // args.parts, (i + 1) * args.spp // args.parts)
                  for i in range(args.parts)]
        futures = [client.submit(render_part, plenum, scene, args.spp, a, b,
                                 os.path.join(workdir, f"part-{i}.plf"), options, pure=False)
                   for i, (a, b) in enumerate(ranges)]
        parts = client.gather(futures)
        rendered = time.perf_counter()
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    merged = subprocess.run([plenum, "merge", *parts, "-o", out], capture_output=True, text=True)
    if merged.returncode != 0:
        sys.exit(f"merge failed ({merged.returncode}): {merged.stderr.strip()}")
    print(f"{args.parts} parts on {args.scheduler or f'{args.workers} local workers'}: "
          f"rendered in {rendered - start:.2f} s, merged in "
          f"{time.perf_counter() - rendered:.2f} s -> {out}")


if __name__ == "__main__":
    main()
