#!/usr/bin/env python3
"""Writes an NFF scene (Haines' SPD format) as a POV-Ray 3.7 scene that traces the same rays
as Plenum's reading of it (docs/nff.md), for timing the two on the same scene.

    python3 docs/bench/nff_to_pov.py scene.nff > scene.pov

What carries over, record by record (docs/nff.md gives Plenum's side):
- `v`: a perspective camera at `from` looking at `at`, `up` as POV's sky; `angle` spans the
  outermost pixel centres, so the edge-to-edge angle is widened by H/(H-1) in tangent, as
  Plenum does. NFF is right-handed and POV-Ray left-handed: `right -x` mirrors it back.
- `b`: the background colour.
- `l`: a point light without falloff; n lights get √n/(2n) each (times a light's colour), and
  the ambient light is the same √n/(2n), as the SPD Readme suggests and Plenum does.
- `f r g b Kd Ks Shine T ior`: pigment r g b with `transmit T`; finish ambient Kd·√n/(2n)
  (POV-Ray multiplies by the pigment, as Plenum's k_a = Kd·colour), diffuse Kd, phong Ks with
  phong_size Shine (no highlight where Shine ≥ 10⁵), reflection Ks; where T > 0, an interior
  of ior (≤ 0 read as 1), so that the refracted ray is traced.
- `s`, `c` (open cones, both radii taken positive), `p` (polygons, even-odd, closed by
  repeating the first vertex, as POV-Ray's polygon wants), `pp` (fanned into smooth
  triangles, each surface's run of patches one mesh, as Plenum makes them).
- The SPD depth: the eye ray and four bounces (POV-Ray's max_trace_level 5, Plenum's NFF
  default `max_depth` 4); no weight cut-off (adc_bailout 0, Plenum's min_weight 0 for NFF).

Shading differs in details that do not change which rays are traced (POV-Ray scales the
local colour by 1 − T; its Phong is not Plenum's exactly), so the images are close, not equal.
"""

import math
import sys


def tokens(text):
    return [w for line in text.splitlines() for w in line.split("#", 1)[0].split()]


def is_number(word):
    try:
        float(word)
        return True
    except ValueError:
        return False


def vec(v):
    return "<%.9g, %.9g, %.9g>" % tuple(v)


def convert(text):
    words = tokens(text)
    at = 0

    def next_word():
        nonlocal at
        at += 1
        return words[at - 1]

    num = lambda: float(next_word())
    triple = lambda: [num(), num(), num()]
    out = []
    camera = None
    background = (0.0, 0.0, 0.0)
    lights = []
    finish = None
    mesh = None  # (finish index, [triangles]) of the current run of patches
    objects = []  # (kind, text, finish index)
    finishes = []

    def close_mesh():
        nonlocal mesh
        if mesh is not None:
            objects.append(("mesh", "\n".join(mesh[1]), mesh[0]))
            mesh = None

    while at < len(words):
        word = next_word()
        if word == "v":
            view = {}
            for _ in range(6):
                key = next_word()
                if key in ("from", "at", "up"):
                    view[key] = triple()
                elif key in ("angle", "hither"):
                    view[key] = num()
                elif key == "resolution":
                    view[key] = (int(num()), int(num()))
                else:
                    raise SystemExit("unexpected view key %r" % key)
            camera = view
        elif word == "b":
            background = triple()
        elif word == "l":
            p = triple()
            # An optional colour: three more numbers before the next record.
            colour = triple() if at < len(words) and is_number(words[at]) else [1.0] * 3
            lights.append((p, colour))
        elif word == "f":
            close_mesh()
            r, g, b = triple()
            kd, ks, shine, tr, ior = num(), num(), num(), num(), num()
            finishes.append((r, g, b, kd, ks, shine, tr, ior))
            finish = len(finishes) - 1
        elif word == "s":
            close_mesh()
            c = triple()
            radius = abs(num())
            objects.append(("sphere", "sphere { %s, %.9g" % (vec(c), radius), finish))
        elif word == "c":
            close_mesh()
            base, br = triple(), abs(num())
            apex, ar = triple(), abs(num())
            objects.append(
                ("cone", "cone { %s, %.9g, %s, %.9g open" % (vec(base), br, vec(apex), ar), finish)
            )
        elif word == "p":
            close_mesh()
            n = int(num())
            pts = [triple() for _ in range(n)]
            body = ", ".join(vec(p) for p in pts + [pts[0]])
            objects.append(("polygon", "polygon { %d, %s" % (n + 1, body), finish))
        elif word == "pp":
            n = int(num())
            verts = [(triple(), triple()) for _ in range(n)]
            if mesh is None or mesh[0] != finish:
                close_mesh()
                mesh = (finish, [])
            for i in range(1, n - 1):
                a, b, c = verts[0], verts[i], verts[i + 1]
                mesh[1].append(
                    "  smooth_triangle { %s, %s, %s, %s, %s, %s }"
                    % (vec(a[0]), vec(a[1]), vec(b[0]), vec(b[1]), vec(c[0]), vec(c[1]))
                )
        else:
            raise SystemExit("unknown NFF record %r" % word)
    close_mesh()
    if camera is None:
        raise SystemExit("no view")

    n = max(len(lights), 1)
    intensity = math.sqrt(n) / (2 * n)
    w, h = camera["resolution"]
    half = math.tan(math.radians(camera["angle"]) / 2) * h / (h - 1)
    # POV-Ray's angle is horizontal; the image may be wider than tall.
    horizontal = 2 * math.degrees(math.atan(half * w / h))
    out.append("// Written by docs/bench/nff_to_pov.py")
    out.append("// resolution %d %d" % (w, h))
    out.append(
        "global_settings { assumed_gamma 1 max_trace_level 5 adc_bailout 0 "
        "ambient_light rgb 1 }"
    )
    out.append("background { rgb %s }" % vec(background))
    out.append(
        "camera { perspective location %s sky %s up y right -x*%.9g angle %.9g look_at %s }"
        % (vec(camera["from"]), vec(camera["up"]), w / h, horizontal, vec(camera["at"]))
    )
    for p, c in lights:
        out.append("light_source { %s rgb %s }" % (vec(p), vec([x * intensity for x in c])))
    for i, (r, g, b, kd, ks, shine, tr, ior) in enumerate(finishes):
        highlight = "phong %.9g phong_size %.9g" % (ks, shine) if shine < 1e5 and ks > 0 else ""
        out.append(
            "#declare T%d = texture { pigment { rgb %s transmit %.9g } "
            "finish { ambient %.9g diffuse %.9g %s reflection %.9g } }"
            % (i, vec([r, g, b]), tr, kd * intensity, kd, highlight, ks)
        )
        inside = "interior { ior %.9g }" % (ior if ior > 0 else 1.0) if tr > 0 else ""
        out.append("#declare I%d = interior { %s }" % (i, inside.removeprefix("interior {").removesuffix("}")))
    for kind, body, f in objects:
        if kind == "mesh":
            out.append("mesh {\n%s\n  texture { T%d } interior { I%d } }" % (body, f, f))
        else:
            out.append("%s texture { T%d } interior { I%d } }" % (body, f, f))
    return "\n".join(out) + "\n"


if __name__ == "__main__":
    with open(sys.argv[1]) as f:
        sys.stdout.write(convert(f.read()))
