#!/usr/bin/env python3
"""The Cornell box of shared/data/references/cbox/ (Mitsuba 3's `mi.cornell_box()`, as
exported to scene.json) built as a LuxCore scene and rendered with LuxCore 2.11's
bidirectional path tracer (BIDIRCPU), with the reference's conventions where LuxCore has
them: 256x256, box filter of one pixel, uniform random samples, matte (Lambertian) RGB
albedos, the one-sided area light at the reference's RGB radiance, timed and optionally
compared with the reference.

    /work/venv-luxcore/bin/python docs/bench/luxcore_cbox.py --seconds 8 --threads 2 --out /tmp/lux.pfm
    ... --spp 64 --out /tmp/lux.exr --compare

Installs with `python3 -m venv /work/venv-luxcore && /work/venv-luxcore/bin/pip install
pyluxcore==2.11.2 numpy openexr` (the wheel brings its own libraries; nothing from apt was
needed on Debian 12). `openexr` is only for EXR files (--out NAME.exr and --compare, which
reads reference.exr); PFM is written with numpy alone.

The translation, property by property:
- camera: `perspective`, the reference's eye, look-at, up and 39.3077 degrees. LuxCore's
  `fieldofview` spans the image's shorter axis; the image is square, so either axis.
  LuxCore 2.11's PerspectiveCamera::InitRay maps film y to raster y as `height - filmY - 1`,
  which puts the image one pixel lower than the reference's (the light's rows were 33-41,
  the reference's 32-40): `scene.camera.screenwindow` is shifted up by one pixel (2/RES) to
  undo it (PATHCPU then matches the reference's edges and mean to 0.05 %).
- geometry: every object's triangles of scene.json, in its winding (LuxCore takes the
  geometric normal from it, as Mitsuba does; the light's faces -y, into the box).
- materials: `matte` with the reference's albedos. LuxCore's matte is two-sided, Mitsuba's
  `diffuse` one-sided: the camera sees no back face here, and the only back faces light can
  reach are the top of the light (1 cm under the ceiling) and the parts of the boxes that are
  under the floor (none: below y = -1 they are enclosed), so the difference is negligible.
- light: the light's `matte` with `emission` = the RGB radiance, `emission.gain` 1,
  `emission.power` 0 and `emission.efficency` 0 (LuxCore's spelling), so that the radiance is
  not rescaled to a power: a pixel that sees the light reads the radiance (checked with
  --check-light). LuxCore's triangle lights emit on the side of the geometric normal only.
- film: `film.filter.type` NONE (each sample in the pixel it falls in: the reference's box
  pixel; BOX with width 0.5 does that in PATHCPU, but in BIDIRCPU it spreads eye samples
  into the neighbouring rows: the light's edges blur and the RMSE triples), the RGB output
  (the film's radiance, light-tracing splats included, no image pipeline, no tone mapping),
  read with Film.GetOutputFloat.
- engine: BIDIRCPU, `sampler.type` RANDOM, `native.threads.count` THREADS, halt by
  `batch.halttime` (--seconds) or `batch.haltspp` (--spp).
- depth: `path.maxdepth` (eye path vertices, default 8) and `light.maxdepth` (light path
  vertices after the light, default 7). LuxCore's BIDIRCPU (SmallVCM's structure) has no cap
  on the *total* length: a path of k bounces is made by eye tracing into the light (k + 1 eye
  vertices), direct light sampling (k), light tracing to the camera (k light vertices) and
  every connection (e eye + l light vertices, e + l = k). With 8 and 7 every path up to 7
  bounces, the reference's limit, has all its strategies and their full MIS weight; paths of
  8 to 15 bounces still get those of their strategies that fit, at their (partial) MIS
  weights. So the image is the reference's plus a part of the light beyond 7 bounces: a little
  brighter. No setting makes it the exact 7-bounce image. Measured (2026-12-03, renders of up to 20 s
  renders): BIDIRCPU is 12 % (red), 5 % (green), 3 % (blue) brighter than the reference, on
  every region but the light (+10-50 %), with 1 or 2 threads, RANDOM or SOBOL; PATHCPU with
  the same scene matches to 0.05 % and at path depth 16 is only 1.8 % (red) brighter, LIGHTCPU
  matches off the light: so most of the excess is BIDIRCPU's own, not the depth limit, and
  is not explained here. Russian roulette: LuxCore's defaults (from depth 3, cap 0.5; unbiased).

Prints one JSON line: renderer, engine, seconds asked for or spp, the render's wall time
(Start to the halt), the whole process's so far, samples per pixel reached (eye samples /
pixels), the light-path count, the image's mean RGB and the output path; with --compare,
the mean against reference.json's and the RMSE against reference.exr (all pixels and
channels).
"""
import argparse
import json
import os
import sys
import time

T_PROCESS = time.perf_counter()
HERE = os.path.dirname(os.path.realpath(__file__))
REF_DIR = os.path.realpath(os.path.join(HERE, "../../../shared/data/references/cbox"))


def parse_args():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    g = p.add_mutually_exclusive_group()
    g.add_argument("--seconds", type=float, help="render for this long (batch.halttime)")
    g.add_argument("--spp", type=int, help="render this many samples per pixel (batch.haltspp)")
    p.add_argument("--threads", type=int, default=2, help="native.threads.count (2)")
    p.add_argument("--eye-depth", type=int, default=8, help="path.maxdepth: eye vertices (8)")
    p.add_argument("--light-depth", type=int, default=7, help="light.maxdepth: light vertices (7)")
    p.add_argument("--engine", default="BIDIRCPU", help="renderengine.type (BIDIRCPU; PATHCPU works too)")
    p.add_argument("--res", type=int, default=256, help="image width and height (256)")
    p.add_argument("--seed", type=int, default=1, help="renderengine.seed (1)")
    p.add_argument("--scene", default=os.path.join(REF_DIR, "scene.json"), help="scene.json of the reference")
    p.add_argument("--out", help="write the image here: .pfm (numpy) or .exr (OpenEXR)")
    p.add_argument("--compare", action="store_true", help="mean and RMSE against the reference")
    p.add_argument("--check-light", action="store_true",
                   help="print the mean of the pixels that see only the light against its radiance")
    p.add_argument("--log", action="store_true", help="show LuxCore's log on stderr")
    return p.parse_args()


def write_pfm(path, img):
    """img: (h, w, 3) float, top row first; PFM stores the bottom row first."""
    import numpy as np
    h, w, _ = img.shape
    with open(path, "wb") as f:
        f.write(b"PF\n%d %d\n-1.0\n" % (w, h))
        f.write(np.ascontiguousarray(img[::-1], dtype="<f4").tobytes())


def read_pfm(path):
    import numpy as np
    with open(path, "rb") as f:
        kind = f.readline().strip()
        dims = f.readline().split()
        while len(dims) < 2:
            dims += f.readline().split()
        w, h = int(dims[0]), int(dims[1])
        scale = float(f.readline())
        data = np.frombuffer(f.read(), dtype="<f4" if scale < 0 else ">f4")
    c = 3 if kind == b"PF" else 1
    img = data[: w * h * c].reshape(h, w, c)[::-1].astype(np.float64)
    return np.repeat(img, 3, axis=-1) if c == 1 else img


def read_exr(path):
    import numpy as np
    import OpenEXR
    ch = OpenEXR.File(path).channels()
    if "RGB" in ch:
        return np.array(ch["RGB"].pixels, dtype=np.float64)[..., :3]
    if "RGBA" in ch:
        return np.array(ch["RGBA"].pixels, dtype=np.float64)[..., :3]
    return np.stack([np.array(ch[k].pixels, dtype=np.float64) for k in ("R", "G", "B")], -1)


def write_exr(path, img):
    import numpy as np
    import OpenEXR
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    OpenEXR.File(header, {"RGB": np.ascontiguousarray(img, dtype=np.float32)}).write(path)


def read_image(path):
    return read_pfm(path) if path.lower().endswith(".pfm") else read_exr(path)


def main():
    args = parse_args()
    if args.seconds is None and args.spp is None:
        args.seconds = 8.0
    import numpy as np
    if args.compare or (args.out or "").lower().endswith(".exr"):
        # before pyluxcore: its wheel preloads TBB's malloc proxy, and OpenEXR's module
        # imported after it aborts in free() (pyluxcore 2.11.2, openexr 3.x)
        import OpenEXR  # noqa: F401
    import pyluxcore
    if args.log:
        pyluxcore.Init()
    else:
        pyluxcore.Init(lambda msg: None)
    scene_json = json.load(open(args.scene))

    scene = pyluxcore.Scene()
    cam = scene_json["camera"]
    sp = pyluxcore.Properties()
    vec = lambda v: " ".join(repr(float(x)) for x in v)
    sp.SetFromString(f"""
scene.camera.type = "perspective"
scene.camera.lookat.orig = {vec(cam["eye"] if "eye" in cam else cam["origin"])}
scene.camera.lookat.target = {vec(cam["look_at"] if "look_at" in cam else cam["target"])}
scene.camera.up = {vec(cam["up"])}
scene.camera.fieldofview = {float(cam.get("fov_deg", cam.get("fov")))!r}
scene.camera.screenwindow = -1 1 {-1.0 - 2.0 / args.res!r} {1.0 - 2.0 / args.res!r}
""")
    for name, m in scene_json["materials"].items():
        sp.SetFromString(f'scene.materials.{name}.type = "matte"\n'
                         f"scene.materials.{name}.kd = {vec(m['albedo'])}\n")
    scene.Parse(sp)
    op = pyluxcore.Properties()
    for obj in scene_json["objects"]:
        name = obj["name"].replace("-", "_")
        verts = [tuple(float(x) for x in v) for v in obj["vertices"]]
        tris = [tuple(int(i) for i in t) for t in obj["triangles"]]
        scene.DefineMesh(name + "_mesh", verts, tris, None, None, None, None)
        mat = obj["material"]
        if "emission" in obj:
            # its own material: the surface's albedo plus the emission, not normalised
            mat = name + "_emitter"
            albedo = scene_json["materials"][obj["material"]]["albedo"]
            op.SetFromString(f"""
scene.materials.{mat}.type = "matte"
scene.materials.{mat}.kd = {vec(albedo)}
scene.materials.{mat}.emission = {vec(obj["emission"])}
scene.materials.{mat}.emission.gain = 1 1 1
scene.materials.{mat}.emission.power = 0
scene.materials.{mat}.emission.efficency = 0
scene.materials.{mat}.emission.normalizebycolor = 0
""")
        op.SetFromString(f'scene.objects.{name}.shape = "{name}_mesh"\n'
                         f'scene.objects.{name}.material = "{mat}"\n')
    scene.Parse(op)

    cfg = pyluxcore.Properties()
    halt = (f"batch.halttime = {args.seconds!r}\nbatch.haltspp = 0" if args.seconds is not None
            else f"batch.haltspp = {args.spp}\nbatch.halttime = 0")
    cfg.SetFromString(f"""
renderengine.type = "{args.engine}"
renderengine.seed = {args.seed}
native.threads.count = {args.threads}
sampler.type = "RANDOM"
path.maxdepth = {args.eye_depth}
light.maxdepth = {args.light_depth}
path.pathdepth.total = {args.eye_depth}
path.pathdepth.diffuse = {args.eye_depth}
path.pathdepth.glossy = {args.eye_depth}
path.pathdepth.specular = {args.eye_depth}
film.width = {args.res}
film.height = {args.res}
film.filter.type = "NONE"
film.filter.width = 0.5
film.outputs.0.type = "RGB"
film.outputs.0.filename = "unused.exr"
film.imagepipelines.0.0.type = "NOP"
film.noiseestimation.warmup = 1000000
{halt}
""")
    config = pyluxcore.RenderConfig(cfg, scene)
    session = pyluxcore.RenderSession(config)
    setup_s = time.perf_counter() - T_PROCESS
    t0 = time.perf_counter()
    session.Start()
    while True:
        time.sleep(0.02)
        session.UpdateStats()
        if session.HasDone():
            break
    render_s = time.perf_counter() - t0
    stats = session.GetStats()
    session.Stop()
    film = session.GetFilm()
    w, h = film.GetWidth(), film.GetHeight()
    buf = np.zeros((h, w, 3), dtype=np.float32)
    film.GetOutputFloat(pyluxcore.FilmOutputType.RGB, buf)
    img = buf[::-1].astype(np.float64)  # LuxCore's film rows run bottom to top

    def stat(key, kind="float"):
        try:
            v = stats.Get(key)
            return v.GetInt() if kind == "int" else v.GetFloat()
        except Exception:
            return None
    eye_samples = film.GetTotalEyeSampleCount() if hasattr(film, "GetTotalEyeSampleCount") else None
    light_samples = film.GetTotalLightSampleCount() if hasattr(film, "GetTotalLightSampleCount") else None
    total = stat("stats.renderengine.total.samplecount")
    spp = (eye_samples if eye_samples else total) / (w * h) if (eye_samples or total) else None

    if args.out:
        (write_pfm if args.out.lower().endswith(".pfm") else write_exr)(args.out, img)
    out = {"renderer": "luxcore", "version": pyluxcore.Version(), "engine": args.engine,
           "threads": args.threads, "eye_depth": args.eye_depth, "light_depth": args.light_depth,
           "halt_seconds": args.seconds, "halt_spp": args.spp,
           "render_s": round(render_s, 4), "setup_s": round(setup_s, 4),
           "process_s_so_far": round(time.perf_counter() - T_PROCESS, 4),
           "spp": spp, "passes": stat("stats.renderengine.pass", "int"),
           "eye_samples": eye_samples, "light_samples": light_samples,
           "mean_rgb": [float(x) for x in img.reshape(-1, 3).mean(0)],
           "image": args.out, "loadavg": os.getloadavg()[0]}
    if args.check_light:
        rad = np.array([o for o in scene_json["objects"] if "emission" in o][0]["emission"])
        # pixels well inside the light's image: the brightest, taken as those above half of it
        lum = img.mean(-1)
        sel = lum > 0.5 * rad.mean()
        out["light_pixels"] = int(sel.sum())
        out["light_pixel_mean"] = [float(x) for x in img[sel].mean(0)] if sel.any() else None
        out["light_radiance"] = rad.tolist()
    if args.compare:
        ref = read_exr(os.path.join(REF_DIR, "reference.exr"))
        ref_mean = json.load(open(os.path.join(REF_DIR, "reference.json")))["mean_rgb"]
        d = img - ref
        out["ref_mean_rgb"] = ref_mean
        out["mean_rel_diff_rgb"] = [float(m / r - 1) for m, r in zip(out["mean_rgb"], ref_mean)]
        out["rmse"] = float(np.sqrt((d * d).mean()))
    print(json.dumps(out), flush=True)
    sys.stderr.flush()
    # pyluxcore 2.11.2 crashes (SIGSEGV) in the interpreter's teardown after a render: leave
    # without it, so that the exit status tells whether the render succeeded
    os._exit(0)


if __name__ == "__main__":
    main()
