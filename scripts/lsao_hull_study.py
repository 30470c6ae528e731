#!/usr/bin/python3
"""Algorithm 1 of Timonen 2013 (the obscure hull), transcribed separately from
core/methods/lsao/lsao.cpp, against brute force on rows of a reference depth buffer.

Sweeps every third row of a 320x180 tile in both horizontal directions, with the paper's
2-D coordinates p_k = (p.xy . D, p.z), fixed sin t = -0.85 and eq. 2, and reports:
- how many samples get a smaller occluder from the hull than from brute force, and whether
  the largest occluder was still on the stack or had been popped;
- the mean normalised obscurance lost, (O_brute - O_hull) / (1 - sin t), when the written
  result also tries the next n entries under the top (n = 0 is the paper's line 20).

Usage: scripts/lsao_hull_study.py [scene ...]   (default: grille room)
Needs the build tree's aolab on PYTHONPATH (scripts/setup.sh installs it). Pure Python:
about a minute per scene.
"""
import math
import pathlib
import sys

import numpy as np

import aolab

SIN_T = -0.85  # §4.1, strategy 3
SEARCH_DEPTHS = (0, 2, 4, 8, 16, 32, None)  # None: the whole stack
ROOT = pathlib.Path(__file__).resolve().parent.parent


def obscurance(h, u, r):
    """Eq. 1 with the fixed tangent (Algorithm 1, line 28) and sin h."""
    length = math.hypot(h[0], h[1])
    sin_h = (h[0] * u[0] + h[1] * u[1]) / length
    return SIN_T + max(0.0, sin_h - SIN_T) * r / (r + length * length), sin_h


def study(scene):
    g = aolab.load_gbuffer(str(ROOT / "reference_scenes" / scene / "reference.exr"))
    depth = np.asarray(g.depth, dtype=np.float64).reshape(g.height, g.width)
    valid = np.asarray(g.valid_mask()).reshape(g.height, g.width) > 0
    r = 0.3 * g.sidecar["ao_distance"] ** 2  # eq. 2's r = C R^2, as LsaoSettings
    x0, y0 = (g.width - 320) // 2, (g.height - 180) // 2
    lost = {n: 0.0 for n in SEARCH_DEPTHS}
    samples = in_stack = popped = 0
    for row in range(y0, y0 + 180, 3):
        for sign in (1, -1):
            columns = range(x0, x0 + 320) if sign > 0 else range(x0 + 319, x0 - 1, -1)
            points, stack = [], []
            for x in columns:
                if not valid[row, x]:
                    continue
                d = depth[row, x]
                p = (sign * (x + 0.5 - g.cx) / g.fx * d, -d)
                norm = math.hypot(*p)
                u = (-p[0] / norm, -p[1] / norm)
                best, best_index = SIN_T, -1
                for i, q in enumerate(points):
                    o = obscurance((q[0] - p[0], q[1] - p[1]), u, r)[0]
                    if o > best:
                        best, best_index = o, i
                tried = []
                if stack:
                    while len(stack) >= 2:  # lines 12-18
                        q1, q2 = points[stack[-1]], points[stack[-2]]
                        o1, s1 = obscurance((q1[0] - p[0], q1[1] - p[1]), u, r)
                        o2, s2 = obscurance((q2[0] - p[0], q2[1] - p[1]), u, r)
                        if not (o1 < o2 and s1 < s2):
                            break
                        stack.pop()
                    for i in reversed(stack):
                        q = points[i]
                        tried.append(obscurance((q[0] - p[0], q[1] - p[1]), u, r)[0])
                for n in SEARCH_DEPTHS:
                    got = max(tried[: None if n is None else n + 1], default=SIN_T)
                    lost[n] += (best - got) / (1.0 - SIN_T)
                if tried and best - tried[0] > 1e-4:
                    if best_index in stack:
                        in_stack += 1
                    else:
                        popped += 1
                samples += 1
                stack.append(len(points))
                points.append(p)
    print(f"{scene}: {samples} samples; hull smaller than brute force for "
          f"{100 * (in_stack + popped) / samples:.1f} % (largest occluder still on the stack: "
          f"{100 * in_stack / samples:.1f} %, popped: {100 * popped / samples:.1f} %)")
    for n in SEARCH_DEPTHS:
        label = "whole stack" if n is None else f"hull_search {n}"
        print(f"  {label:>15}: mean normalised obscurance lost {100 * lost[n] / samples:.3f} %")


if __name__ == "__main__":
    for name in sys.argv[1:] or ["grille", "room"]:
        study(name)
