#!/usr/bin/env python3
"""Writes drum3d_shell.stl: the open cylindrical shell of the 3-D drum (radius
0.1 m, length 0.05 m along y from y = 0, 64 sides), facets facing the axis, in
millimetres as CAD tools export it (the scene scales by 1e-3).

    python3 make_shell_stl.py [RADIUS_MM LENGTH_MM SIDES]
"""
import math
import sys

radius, length, sides = 100.0, 50.0, 64
if len(sys.argv) == 4:
    radius, length, sides = float(sys.argv[1]), float(sys.argv[2]), int(sys.argv[3])


def point(k, y):
    a = 2.0 * math.pi * k / sides
    return (radius * math.cos(a), y, radius * math.sin(a))


def facet(out, a, b, c):
    u = [b[i] - a[i] for i in range(3)]
    v = [c[i] - a[i] for i in range(3)]
    n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]
    norm = math.sqrt(sum(x * x for x in n))
    out.append("  facet normal %.6e %.6e %.6e\n    outer loop\n" % tuple(x / norm for x in n))
    for p in (a, b, c):
        out.append("      vertex %.6f %.6f %.6f\n" % p)
    out.append("    endloop\n  endfacet\n")


out = ["solid drum3d_shell\n"]
for k in range(sides):
    a0, a1 = point(k, 0.0), point(k + 1, 0.0)
    b0, b1 = point(k, length), point(k + 1, length)
    # Counter-clockwise seen from the axis: the normal points inwards.
    facet(out, a0, a1, b0)
    facet(out, a1, b1, b0)
out.append("endsolid drum3d_shell\n")
with open("drum3d_shell.stl", "w") as f:
    f.writelines(out)
