"""Corpus family `terrain`: landscapes: the Terragen height field of assimp-testmodels
(RealisticTerrain_Large.ter, 513 x 513 points) and seeded noise terrains (ridged mountains,
a canyon). Metres, z up; height fields of two triangles a cell, flat-shaded.
"""
import math
import os
import struct

import mathutils
from mathutils import Vector

from families import kit

TER = "TER/RealisticTerrain_Large.ter"


def read_terragen(relpath):
    """The heights (metres) of a Terragen .ter file and its point spacing (metres): the
    SIZE/XPTS/YPTS/SCAL/CRAD/CRVM chunks, then ALTW (height scale, base height, int16s)."""
    path = os.path.join(kit.MODELS, relpath)
    if not os.path.isfile(path):
        raise FileNotFoundError("%s not found: install Debian's assimp-testmodels package" % path)
    data = open(path, "rb").read()
    if data[:16] != b"TERRAGENTERRAIN ":
        raise ValueError("%s is not a Terragen terrain" % path)
    pos, size, xpts, ypts, scale = 16, None, None, None, (30.0, 30.0, 30.0)
    while pos < len(data):
        tag = data[pos:pos + 4]
        pos += 4
        if tag in (b"SIZE", b"XPTS", b"YPTS"):
            value = struct.unpack_from("<h", data, pos)[0]
            size, xpts, ypts = ((value, xpts, ypts) if tag == b"SIZE" else
                                (size, value, ypts) if tag == b"XPTS" else (size, xpts, value))
            pos += 4
        elif tag == b"SCAL":
            scale = struct.unpack_from("<3f", data, pos)
            pos += 12
        elif tag in (b"CRAD", b"CRVM"):
            pos += 4
        elif tag == b"ALTW":
            height_scale, base = struct.unpack_from("<hh", data, pos)
            pos += 4
            nx, ny = xpts or size + 1, ypts or size + 1
            raw = struct.unpack_from("<%dh" % (nx * ny), data, pos)
            rows = [[(base + raw[j * nx + i] * height_scale / 65536.0) * scale[2]
                     for i in range(nx)] for j in range(ny)]
            return rows, scale[0]
        else:
            raise ValueError("%s: unknown Terragen chunk %r" % (path, tag))
    raise ValueError("%s has no ALTW chunk" % path)


def terragen(b, r, stride, window):
    """Every stride-th point of the window (i0, j0, count) of the .ter file, centred."""
    rows, spacing = read_terragen(TER)
    i0, j0, n = window
    sub = [[rows[j][i] for i in range(i0, i0 + n * stride, stride)]
           for j in range(j0, j0 + n * stride, stride)]
    base = min(min(row) for row in sub)
    sub = [[h - base for h in row] for row in sub]
    step = spacing * stride
    b.grid(sub, -step * (n - 1) / 2, -step * (n - 1) / 2, step)
    return sub, step


def ter_wide(b, r):
    terragen(b, r, 4, (0, 0, 128))


def ter_close(b, r):
    """A 2.5 km window at full resolution, with boulders on the slope near the camera."""
    sub, step = terragen(b, r, 1, (200, 200, 128))
    for k in range(10):
        i, j = int(r.uniform(40, 80)), int(r.uniform(10, 40))
        x, y = -step * 127 / 2 + i * step, -step * 127 / 2 + j * step
        s = r.uniform(3.0, 9.0)
        b.rock((x, y, sub[j][i] - 0.5), (s, s * 0.8, s * 0.6), seed=r.uniform(0.0, 100.0))


def noise_heights(n, step, seed, fn):
    shift = Vector((seed * 13.7, seed * 5.1, 0.0))
    return [[fn(Vector((i * step, j * step, 0.0)), shift) for i in range(n)] for j in range(n)]


def ridged(b, r):
    """Ridged multifractal mountains, 160 x 160 points 5 m apart."""
    def height(p, shift):
        q = p / 300.0 + shift
        return 90.0 * mathutils.noise.ridged_multi_fractal(
            q, 1.0, 2.0, 6, 1.0, 2.0, noise_basis='PERLIN_ORIGINAL')
    b.grid(noise_heights(160, 5.0, r.uniform(0.0, 50.0), height), -400.0, -400.0, 5.0)


def canyon(b, r):
    """A winding river canyon: fBm hills with a valley 40 m deep along a seeded meander."""
    phase = r.uniform(0.0, 6.28)

    def height(p, shift):
        hills = 12.0 * mathutils.noise.fractal(
            p / 60.0 + shift, 0.9, 2.0, 5, noise_basis='PERLIN_ORIGINAL')
        centre = 25.0 * math.sin(p.y / 45.0 + phase)
        d = abs(p.x - 200.0 - centre)
        wall = 40.0 * min(1.0, max(0.0, (d - 8.0) / 18.0)) ** 0.6
        ledges = 3.0 * math.floor(wall / 3.0)   # terraces in the walls
        return hills + 0.5 * (wall + ledges)
    b.grid(noise_heights(161, 2.5, r.uniform(0.0, 50.0), height), 0.0, 0.0, 2.5)


# variant: (seed, builder, camera at, target, lens mm, R)
VARIANTS = {
    0: (61, ter_wide, (2500.0, -4200.0, 2400.0), (0.0, 0.0, 0.0), 28.0, 120.0),
    1: (62, ter_close, (300.0, -1250.0, 700.0), (0.0, 0.0, 150.0), 24.0, 20.0),
    2: (63, ridged, (300.0, -450.0, 260.0), (0.0, 0.0, 20.0), 24.0, 12.0),
    3: (64, canyon, (200.0, 10.0, 12.0), (200.0, 200.0, 8.0), 20.0, 4.0),
}


def build(variant):
    seed, builder, at, target, lens, radius = VARIANTS[variant]
    b = kit.Builder()
    builder(b, kit.rng(seed))
    b.build("Terrain", kit.grey())
    kit.finish(at, target, lens, radius, clip_start=0.5, clip_end=20000.0)
