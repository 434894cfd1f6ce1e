"""Writes a mesh as raw little-endian arrays for harness.c, read with the shared benchmark's
own OBJ/PLY reader so that triangles are numbered as in the hits files:
u64 vertex count, u64 triangle count, f32 x y z per vertex, u32 a b c per triangle.

    python3 docs/bench/embree/dump_mesh.py MESH OUT.raw
"""
import os
import struct
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "../../../../shared/bench"))
import make_rays  # noqa: E402

mesh = make_rays.load_mesh(sys.argv[1])
with open(sys.argv[2], "wb") as f:
    f.write(struct.pack("<QQ", mesh.nv, mesh.ntri))
    f.write(struct.pack("<%df" % len(mesh.v), *mesh.v))
    f.write(struct.pack("<%dI" % len(mesh.tri), *mesh.tri))
