#!/usr/bin/env python3
"""The reference run beside `pcpp plan` in `npm run bench` (issue 15): what
a user's own script would do at the least, load the scan with trimesh and
project the drawing's points onto it with Embree (vertical rays from above,
the highest hit), nothing else.

    reference_trimesh.py SCAN PROGRAM.gcode

The points are the XY of the G1 moves of a program pcpp wrote for the same
drawing, so both project the same number of points.
"""
import re
import sys

import numpy as np
import trimesh

XY = re.compile(r"^G1\b[^;(]*?X(-?[0-9.]+)\s+Y(-?[0-9.]+)")


def main():
    scan, program = sys.argv[1], sys.argv[2]
    if not trimesh.ray.has_embree:
        sys.exit("[bench] trimesh runs without Embree here")
    mesh = trimesh.load(scan, force="mesh")
    with open(program) as f:
        xy = np.array([[float(m[1]), float(m[2])] for m in map(XY.match, f) if m])
    top = mesh.bounds[1][2] + 1.0
    origins = np.column_stack([xy, np.full(len(xy), top)])
    directions = np.tile([0.0, 0.0, -1.0], (len(xy), 1))
    hits, rays, _ = mesh.ray.intersects_location(origins, directions, multiple_hits=False)
    print(f"{len(xy)} points, {len(set(rays.tolist()))} hit, {len(mesh.faces)} faces")


if __name__ == "__main__":
    main()
