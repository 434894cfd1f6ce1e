#!/usr/bin/env python3
"""An image against a reference (the Cornell box's in shared/data/references/cbox/, or any
pair of EXRs of the same size): the mean per channel, the RMSE and the relative RMSE, and
the per-pixel z-test of the reference's README.

    /work/venv-mitsuba/bin/python docs/bench/mitsuba_compare.py IMAGE.exr REFERENCE.exr \
        [--ref-var REFERENCE-variance.exr] [--var-img IMAGE-variance.exr] [--json] [--check]

Both variance files hold, per pixel and channel, the variance *of the pixel's mean* (for a
render of n samples: the per-sample variance / n; for the reference, the sample variance of
its 16 renders / 16). --ref-var defaults to the reference's name with "-variance" before
the extension. For each pixel channel,
    z = |image - reference| / sqrt(var_img + var_ref),   p = 2 (1 - Phi(z)) = erfc(z / sqrt 2),
and the channel passes when p > alpha = 1 - 0.99^(1/N), N the number of pixel channels
(Sidak's correction: with an unbiased image, all N pass with probability 0.99). The
README's criterion: at least 99.75 % of the channels pass (--min-pass); --check exits 1
below it. Where var_img + var_ref is 0 (pixels that see nothing, or only the light), the
channel passes when the two values agree to 1e-6 (relative).

Without --var-img the test uses the reference's variance alone and says so: a noisy image
then fails it unless the image is itself converged (far more samples than the reference's
16,384 per pixel would need), so read that pass rate as a measure of noise, not of bias.
(Mitsuba's own render tests, src/render/tests/test_renders.py, instead take the reference's
per-sample variance and the image's sample count; the two agree where the image's noise
is the reference's per-sample noise.)

EXRs are read with mitsuba's mi.Bitmap (variant scalar_rgb, no LLVM needed), RGB channels
(an alpha channel is dropped).
"""
import argparse
import json
import math
import os
import sys

import numpy as np


def read_exr(path):
    import mitsuba as mi
    if mi.variant() is None:
        mi.set_variant("scalar_rgb")
    bmp = mi.Bitmap(path)
    a = np.array(bmp, dtype=np.float64)
    if a.ndim == 2:
        a = a[..., None]
    if a.shape[-1] == 1:
        a = np.repeat(a, 3, axis=-1)
    return a[..., :3]


def z_critical(alpha):
    """The z at which erfc(z / sqrt 2) = alpha, by bisection."""
    lo, hi = 0.0, 40.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if math.erfc(mid / math.sqrt(2.0)) > alpha:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def compare(img, ref, var_ref, var_img=None, significance=0.01):
    if img.shape != ref.shape:
        raise SystemExit(f"image {img.shape[1]}x{img.shape[0]} and reference "
                         f"{ref.shape[1]}x{ref.shape[0]} differ in size")
    d = (img - ref).reshape(-1, 3)
    mse_c = (d * d).mean(0)
    ref_mean = ref.reshape(-1, 3).mean(0)
    out = {
        "mean_rgb": img.reshape(-1, 3).mean(0).tolist(),
        "ref_mean_rgb": ref_mean.tolist(),
        "mean_rel_diff_rgb": (img.reshape(-1, 3).mean(0) / ref_mean - 1).tolist(),
        "rmse_rgb": np.sqrt(mse_c).tolist(),
        "rmse": float(np.sqrt(mse_c.mean())),
        # RMSE relative to the reference's mean value (per channel, and over all channels)
        "rel_rmse_rgb": (np.sqrt(mse_c) / ref_mean).tolist(),
        "rel_rmse": float(np.sqrt(mse_c.mean()) / ref_mean.mean()),
    }
    if var_ref is not None:
        # the reference's own noise, taken out of the MSE (it adds its mean variance)
        vr = var_ref.reshape(-1, 3)
        out["rmse_less_ref_noise"] = float(np.sqrt(max(mse_c.mean() - vr.mean(), 0.0)))
        n = d.size
        alpha = 1.0 - (1.0 - significance) ** (1.0 / n)
        zc = z_critical(alpha)
        var = vr + (var_img.reshape(-1, 3) if var_img is not None else 0.0)
        ad = np.abs(d)
        with np.errstate(divide="ignore", invalid="ignore"):
            z = np.where(var > 0, ad / np.sqrt(var), 0.0)
        degenerate = var <= 0
        tol = 1e-6 * np.maximum(1.0, np.abs(ref.reshape(-1, 3)))
        passed = np.where(degenerate, ad <= tol, z < zc)  # z < zc  <=>  p > alpha
        zs = np.where(degenerate, 0.0, z)
        worst = np.argsort(zs.ravel())[::-1][:5]
        w = ref.shape[1]
        out["ztest"] = {
            "variances": "image + reference" if var_img is not None else "reference only",
            "channels": int(n),
            "alpha": alpha,
            "z_critical": zc,
            "pass_fraction": float(passed.mean()),
            "failing": int((~passed).sum()),
            "degenerate_channels": int(degenerate.sum()),
            "mean_z": float(zs[~degenerate].mean()) if (~degenerate).any() else 0.0,
            "max_z": float(zs.max()),
            "worst": [{"x": int(i // 3 % w), "y": int(i // 3 // w), "c": "RGB"[i % 3],
                       "z": float(zs.ravel()[i])} for i in worst],
        }
    return out


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("image")
    p.add_argument("reference")
    p.add_argument("--ref-var", help="the reference's variance EXR (default: REFERENCE-variance.exr)")
    p.add_argument("--var-img", help="the image's variance EXR (variance of each pixel's mean)")
    p.add_argument("--significance", type=float, default=0.01,
                   help="family-wise significance of the z-test (0.01: alpha = 1 - 0.99^(1/N))")
    p.add_argument("--min-pass", type=float, default=0.9975,
                   help="pass fraction the test asks for (0.9975)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--check", action="store_true", help="exit 1 when the z-test fails")
    a = p.parse_args()
    ref_var_path = a.ref_var
    if ref_var_path is None:
        stem, ext = os.path.splitext(a.reference)
        if os.path.exists(stem + "-variance" + ext):
            ref_var_path = stem + "-variance" + ext
    img, ref = read_exr(a.image), read_exr(a.reference)
    var_ref = read_exr(ref_var_path) if ref_var_path else None
    var_img = read_exr(a.var_img) if a.var_img else None
    r = compare(img, ref, var_ref, var_img, a.significance)
    r.update({"image": a.image, "reference": a.reference, "ref_var": ref_var_path,
              "var_img": a.var_img})
    ok = None
    if "ztest" in r:
        ok = r["ztest"]["pass_fraction"] >= a.min_pass
        r["ztest"]["min_pass"] = a.min_pass
        r["ztest"]["passed"] = ok
    if a.json:
        print(json.dumps(r))
    else:
        f = lambda v: " ".join(f"{x:.6g}" for x in v)
        print(f"image      {a.image}\nreference  {a.reference}")
        print(f"mean RGB   {f(r['mean_rgb'])}   reference {f(r['ref_mean_rgb'])}   "
              f"relative difference {' '.join(f'{x:+.3%}' for x in r['mean_rel_diff_rgb'])}")
        print(f"RMSE       {r['rmse']:.6g}  (RGB {f(r['rmse_rgb'])})")
        print(f"rel. RMSE  {r['rel_rmse']:.4%}  (RGB {' '.join(f'{x:.4%}' for x in r['rel_rmse_rgb'])})"
              "   [RMSE / reference mean]")
        if "rmse_less_ref_noise" in r:
            print(f"RMSE less the reference's noise  {r['rmse_less_ref_noise']:.6g}")
        if "ztest" in r:
            z = r["ztest"]
            print(f"z-test     {z['pass_fraction']:.4%} of {z['channels']} pixel channels pass "
                  f"(p > alpha = {z['alpha']:.3g}, z < {z['z_critical']:.3f}); {z['failing']} fail; "
                  f"variances: {z['variances']}; {z['degenerate_channels']} with zero variance; "
                  f"max z {z['max_z']:.2f}")
            if var_img is None:
                print("           (no --var-img: the reference's variance only; a noisy image "
                      "fails this by its noise, not its bias)")
            print(f"           {'PASS' if ok else 'FAIL'} (asks for {a.min_pass:.2%})")
        else:
            print("z-test     skipped: no reference variance")
    if a.check and ok is False:
        sys.exit(1)


if __name__ == "__main__":
    main()
