#!/usr/bin/env python3
"""Mitsuba 3's Cornell box (`mi.cornell_box()`) rendered with the conventions of the reference
in shared/data/references/cbox/ (256x256, box filter, independent sampler, `path` with
max_depth 8 = at most 7 bounces, Russian roulette from depth 5), timed and compared with
the reference.

    export DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM-19.so
    /work/venv-mitsuba/bin/python docs/bench/mitsuba_cbox.py --spp 64 --threads 2 --rounds 5
    ... --variant llvm_ad_spectral --out /tmp/mi-spectral.exr --var-out /tmp/mi-spectral-var.exr

Prints JSON lines on stdout: one {"event": "first"} (the first render in this process: the
tracing of the Python/C++ program, LLVM code generation and compilation, or a load from
Dr.Jit's kernel cache in ~/.drjit, and the run), one {"event": "steady"} per further round
(same scene and program, a new seed: tracing and an in-memory kernel-cache hit, no
compilation), then {"event": "summary"} with the median of the steady rounds, the image's
mean against reference.json's, and its RMSE against the reference EXR per channel and
overall. With --cold-cache, HOME is pointed at an empty temporary folder before Dr.Jit is
imported, so the first render compiles from scratch (Dr.Jit keeps its kernel cache in
$HOME/.drjit); otherwise "kernels" in the first event says whether the disk cache served it.

--out writes the first render (spp samples per pixel); --var-out writes, per pixel and
channel, the sample variance over the ROUNDS steady renders (each of spp samples,
independent seeds, the first render left out so that the estimate is independent of it),
which is the variance of the mean of one render: the companion of --out for
mitsuba_compare.py's z-test (use --rounds 16 or more: the reference's own has 15 degrees
of freedom). Timings are wall clock (time.perf_counter) around
mi.render and the evaluation of its result; the load average is recorded next to each,
since the project's machines are shared.
"""
import argparse
import atexit
import json
import os
import resource
import shutil
import statistics
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.realpath(__file__))
REF_DIR = os.path.realpath(os.path.join(HERE, "../../../shared/data/references/cbox"))


def parse_args():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--spp", type=int, default=64, help="samples per pixel per render (64)")
    p.add_argument("--variant", default="llvm_ad_rgb",
                   help="llvm_ad_rgb (default) or llvm_ad_spectral (or any Mitsuba variant)")
    p.add_argument("--threads", type=int, default=2,
                   help="dr.set_thread_count(N): N threads in all, the calling thread included "
                        "(N-1 workers); default 2")
    p.add_argument("--rounds", type=int, default=5,
                   help="steady renders after the first (default 5; 0: the first only)")
    p.add_argument("--max-depth", type=int, default=8,
                   help="Mitsuba's max_depth, in path segments (8 = 7 bounces, the reference's)")
    p.add_argument("--res", type=int, default=256, help="image width and height (256)")
    p.add_argument("--seed", type=int, default=0, help="seed of the first render; round i: seed+i")
    p.add_argument("--out", help="write the first render here (EXR, linear sRGB)")
    p.add_argument("--var-out", help="write the variance over the 1+ROUNDS renders here (EXR)")
    p.add_argument("--ref", help="reference EXR (default: the reference of the variant's mode)")
    p.add_argument("--ref-var", help="reference variance EXR (default: beside --ref)")
    p.add_argument("--cold-cache", action="store_true",
                   help="use an empty Dr.Jit kernel cache (HOME set to a temporary folder)")
    p.add_argument("--no-compare", action="store_true",
                   help="skip the reference (no EXR reads: for whole-process timings)")
    p.add_argument("--quiet-summary", action="store_true", help="print only the summary line")
    return p.parse_args()


def reference_paths(args):
    spectral = "spectral" in args.variant
    ref = args.ref or os.path.join(REF_DIR, "reference-spectral.exr" if spectral else "reference.exr")
    if args.ref_var:
        ref_var = args.ref_var
    else:
        stem, ext = os.path.splitext(ref)
        ref_var = stem + "-variance" + ext
    meta = os.path.splitext(ref)[0] + ".json"
    return ref, ref_var, meta


def main():
    args = parse_args()
    if args.cold_cache:
        os.environ["HOME"] = tempfile.mkdtemp(prefix="drjit-cold-")
        atexit.register(shutil.rmtree, os.environ["HOME"], True)
    if "llvm" in args.variant and not os.environ.get("DRJIT_LIBLLVM_PATH"):
        default = "/usr/lib/x86_64-linux-gnu/libLLVM-19.so"
        if os.path.exists(default):
            os.environ["DRJIT_LIBLLVM_PATH"] = default
    t_import = time.perf_counter()
    import numpy as np
    import drjit as dr
    import mitsuba as mi
    mi.set_variant(args.variant)
    dr.set_thread_count(args.threads)
    import_s = time.perf_counter() - t_import

    def bitmap_io(fn):
        # Bitmap's EXR reader and writer hang when Dr.Jit's pool has no worker thread
        # (--threads 1, Mitsuba 3.9.1): give them two threads for the I/O only.
        if args.threads < 2:
            dr.set_thread_count(2)
        try:
            return fn()
        finally:
            dr.set_thread_count(args.threads)

    def emit(obj):
        if not args.quiet_summary or obj.get("event") == "summary":
            print(json.dumps(obj), flush=True)

    scene_dict = mi.cornell_box()
    sensor = scene_dict["sensor"]
    sensor["film"]["width"] = sensor["film"]["height"] = args.res
    sensor["film"]["rfilter"] = {"type": "box"}
    sensor["sampler"] = {"type": "independent", "sample_count": args.spp}
    scene_dict["integrator"] = {"type": "path", "max_depth": args.max_depth}  # rr_depth 5: default
    t0 = time.perf_counter()
    scene = mi.load_dict(scene_dict)
    load_s = time.perf_counter() - t0

    def cpu():
        r = resource.getrusage(resource.RUSAGE_SELF)
        return r.ru_utime + r.ru_stime

    cpu_s = []  # CPU time of this process per render: about threads x wall when not crowded

    def render(seed):
        c = cpu()
        t = time.perf_counter()
        img = mi.render(scene, spp=args.spp, seed=seed)
        dr.eval(img)
        dr.sync_thread()
        s = time.perf_counter() - t
        cpu_s.append(cpu() - c)
        return np.array(img, dtype=np.float64), s

    # The first render, with kernel metadata: was it compiled, or loaded from the disk cache?
    dr.kernel_history_clear()
    with dr.scoped_set_flag(dr.JitFlag.KernelHistory, True):
        first, first_s = render(args.seed)
        hist = dr.kernel_history()
    jit = [h for h in hist if h.get("type") == dr.KernelType.JIT]
    kernels = {
        "count": len(jit),
        "compiled": sum(1 for h in jit if not h.get("cache_hit")),
        "from_disk_cache": sum(1 for h in jit if h.get("cache_disk")),
        "codegen_ms": round(sum(h.get("codegen_time", 0.0) for h in jit), 2),
        "backend_ms": round(sum(h.get("backend_time", 0.0) for h in jit), 2),
        "execution_ms": round(sum(h.get("execution_time", 0.0) for h in jit), 2),
    }
    emit({"event": "first", "variant": args.variant, "spp": args.spp, "seed": args.seed,
          "threads": dr.thread_count(), "seconds": round(first_s, 4), "cpu_s": round(cpu_s[-1], 3), "import_s": round(import_s, 3),
          "load_scene_s": round(load_s, 4), "kernels": kernels, "loadavg": os.getloadavg()[0]})

    steady = []
    acc, acc2, n = first.copy(), first * first, 1
    images = [first]
    for i in range(1, args.rounds + 1):
        img, s = render(args.seed + i)
        steady.append(s)
        images.append(img)
        acc += img
        acc2 += img * img
        n += 1
        emit({"event": "steady", "round": i, "seconds": round(s, 4), "cpu_s": round(cpu_s[-1], 3), "loadavg": os.getloadavg()[0]})

    if args.out:
        bitmap_io(lambda: mi.Bitmap(first.astype(np.float32), mi.Bitmap.PixelFormat.RGB).write(args.out))
    if args.var_out:
        # From the steady rounds only: an estimate that includes the image it is tested with
        # bounds that image's z by sqrt(n - 1) (3.9 for 16 renders), below the test's 5.4.
        m = n - 1
        if m < 2:
            sys.exit("--var-out needs --rounds 2 or more")
        s1, s2 = acc - first, acc2 - first * first
        mean = s1 / m
        var = np.maximum(s2 / m - mean * mean, 0.0) * m / (m - 1)
        bitmap_io(lambda: mi.Bitmap(var.astype(np.float32), mi.Bitmap.PixelFormat.RGB).write(args.var_out))

    summary = {"event": "summary", "variant": args.variant, "spp": args.spp,
               "res": args.res, "max_depth": args.max_depth, "threads": dr.thread_count(),
               "mitsuba": mi.__version__, "drjit": dr.__version__,
               "first_s": round(first_s, 4),
               "steady_median_s": round(statistics.median(steady), 4) if steady else None,
               "steady_s": [round(s, 4) for s in steady],
               "first_cpu_s": round(cpu_s[0], 3),
               "steady_cpu_median_s": round(statistics.median(cpu_s[1:]), 3) if steady else None,
               "cpu_per_wall": round(sum(cpu_s) / (first_s + sum(steady)), 3),
               "load_scene_s": round(load_s, 4), "import_s": round(import_s, 3),
               "mean_rgb": [float(x) for x in first.reshape(-1, 3).mean(0)],
               "renders": n,
               "mean_rgb_all": [float(x) for x in (acc / n).reshape(-1, 3).mean(0)]}
    ref_path, ref_var_path, meta_path = reference_paths(args)
    if os.path.exists(ref_path) and args.res == 256 and not args.no_compare:
        ref = np.array(bitmap_io(lambda: mi.Bitmap(ref_path)), dtype=np.float64)[..., :3]
        d = (first - ref).reshape(-1, 3)
        mse_c = (d * d).mean(0)
        summary["reference"] = ref_path
        summary["rmse_rgb"] = [float(x) for x in np.sqrt(mse_c)]
        summary["rmse"] = float(np.sqrt(mse_c.mean()))
        # every render's RMSE (first and steady rounds: independent seeds), for its spread
        summary["rmse_all"] = [float(np.sqrt(((im - ref) ** 2).mean())) for im in images]
        summary["rmse_median"] = float(statistics.median(summary["rmse_all"]))
        summary["ref_mean_from_exr"] = [float(x) for x in ref.reshape(-1, 3).mean(0)]
        if os.path.exists(ref_var_path):
            ref_var = np.array(bitmap_io(lambda: mi.Bitmap(ref_var_path)), dtype=np.float64)[..., :3].reshape(-1, 3)
            # The reference's own noise inflates the MSE by its mean variance; take it out.
            summary["rmse_less_ref_noise"] = float(np.sqrt(max(mse_c.mean() - ref_var.mean(), 0.0)))
            # The standard error of this image's mean per channel, predicted from the
            # reference's variance (of a 16,384-spp mean) scaled to spp samples.
            spp_ref = 16384
            if os.path.exists(meta_path):
                spp_ref = json.load(open(meta_path)).get("spp_total", spp_ref)
            pix_var = ref_var * (spp_ref / args.spp) + ref_var
            summary["mean_stderr_rgb"] = [float(x) for x in np.sqrt(pix_var.sum(0)) / len(pix_var)]
        if os.path.exists(meta_path):
            ref_mean = json.load(open(meta_path))["mean_rgb"]
            summary["ref_mean_rgb"] = ref_mean
            summary["mean_rel_diff_rgb"] = [float(m / r - 1) for m, r in
                                            zip(summary["mean_rgb"], ref_mean)]
            summary["mean_all_rel_diff_rgb"] = [float(m / r - 1) for m, r in
                                                zip(summary["mean_rgb_all"], ref_mean)]
            if "mean_stderr_rgb" in summary:
                # z of the first render's mean, and of the mean of all n renders (n x the samples)
                summary["mean_z_rgb"] = [float((m - r) / s) for m, r, s in
                                         zip(summary["mean_rgb"], ref_mean, summary["mean_stderr_rgb"])]
                se_all = np.sqrt((ref_var * (spp_ref / (n * args.spp)) + ref_var).sum(0)) / len(ref_var)
                summary["mean_all_z_rgb"] = [float((m - r) / s) for m, r, s in
                                             zip(summary["mean_rgb_all"], ref_mean, se_all)]
    emit(summary)


if __name__ == "__main__":
    main()
