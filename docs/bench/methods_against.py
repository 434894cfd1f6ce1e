#!/usr/bin/env python3
"""Every method's render time against another build of Plenum, in one run.

    git worktree add /tmp/base REV && cargo build --release --manifest-path /tmp/base/Cargo.toml
    cargo build --release -p plenum-cli
    python3 docs/bench/methods_against.py --base /tmp/base/target/release/plenum \\
        --new target/release/plenum --rounds 3

Each scene (the built-in one, scenes/cornell-box.toml and scenes/glass.toml unless
`--scenes` names others) is rendered by every method at 160×120 with the samples of `SPP`
(about a second each; random sampler, seed 1, 2 threads, the scene's colour mode unless
`--color` names one for the physically based methods), by the base build and the new one in turn, `--rounds`
times over, so that the machine's drift falls on both alike. A run's time is the render's own
as Plenum reports it ("…, T s, method"), without loading. Prints, per scene and method, the
median times and new ÷ base; at the end the largest ratio. Both builds must take the same
options; the images themselves are not compared (the tests do that).
"""
import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile

SPP = {
    "local": 512,
    "appel": 256,
    "whitted": 128,
    "path": 64,
    "light": 64,
    "bdpt": 32,
    "photon": 16,
    "sppm": 32,
}
TIME = re.compile(r"spp, ([0-9.]+) s, ")


def render(plenum, scene, method, out, color):
    args = [plenum, "render"] + ([scene] if scene != "builtin" else [])
    args += ["--color", color] if color else []
    args += ["--integrator", method, "--spp", str(SPP[method]), "--sampler", "random"]
    args += ["--seed", "1", "--threads", "2", "--width", "160", "--height", "120", "-o", out]
    p = subprocess.run(args, capture_output=True, text=True, timeout=600)
    if p.returncode != 0:
        sys.exit(f"{' '.join(args)} failed:\n{p.stderr}")
    m = TIME.search(p.stderr)
    if not m:
        sys.exit(f"no render time in the output of {' '.join(args)}:\n{p.stderr}")
    return float(m.group(1))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--base", required=True)
    ap.add_argument("--new", required=True)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--scenes", nargs="*", default=["builtin", "scenes/cornell-box.toml", "scenes/glass.toml"])
    ap.add_argument("--methods", nargs="*", default=list(SPP))
    ap.add_argument("--color", help="rgb or spectral for the physically based methods (default: the scene's)")
    a = ap.parse_args()
    times = {}
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "image.pfm")
        for r in range(a.rounds):
            for scene in a.scenes:
                for method in a.methods:
                    for build, plenum in (("base", a.base), ("new", a.new)):
                        pb = method not in ("local", "appel", "whitted")
                        t = render(plenum, scene, method, out, a.color if pb else None)
                        times.setdefault((scene, method, build), []).append(t)
            print(f"round {r + 1} of {a.rounds} done", file=sys.stderr)
    print(f"| scene | method | spp | base (s) | new (s) | new ÷ base |")
    print(f"|---|---|---|---|---|---|")
    worst = (0.0, None)
    for scene in a.scenes:
        for method in a.methods:
            base = statistics.median(times[(scene, method, "base")])
            new = statistics.median(times[(scene, method, "new")])
            ratio = new / base
            worst = max(worst, (ratio, (scene, method)))
            name = os.path.basename(scene)
            print(f"| {name} | {method} | {SPP[method]} | {base:.3f} | {new:.3f} | {ratio:.3f} |")
    print(f"\nlargest new ÷ base: {worst[0]:.3f} ({worst[1][0]}, {worst[1][1]})")


if __name__ == "__main__":
    main()
