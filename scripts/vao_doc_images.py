#!/usr/bin/python3
"""Images and scores for docs/methods/vao.md and vao_pp.md: VAO and VAO++ with each VAO++
extension switched off in turn on the room reference (vs Cycles), and colour bleeding and
luminance sensitivity on the `blocks` analytic scene with a synthetic colour buffer and on
the colored_room reference with Cycles' DiffCol and Emit passes. Run after scripts/build.sh:

    PYTHONPATH=build/python /usr/bin/python3 scripts/vao_doc_images.py

Writes docs/images/room_vao*.png, blocks_vao_pp_*.png and colored_room_vao_pp_*.png; prints
Markdown tables.
"""
import time
from pathlib import Path

import numpy as np

import aolab
from aolab.scoring import signed_error_rgb

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "images"

VARIANTS = [
    ("vao", {}, "VAO, defaults (16 samples, spiral, random rotation)"),
    ("vao", dict(view_ray_pipes=False), "VAO, pipes parallel to the view axis (paper)"),
    ("vao_pp", {}, "VAO++, defaults"),
    ("vao_pp", dict(adaptive_sampling=False), "VAO++ without adaptive sampling"),
    ("vao_pp", dict(culling="off"), "VAO++ without culling"),
    ("vao_pp", dict(culling="greedy"), "VAO++ with greedy culling"),
    ("vao_pp", dict(range_check=False), "VAO++ without range check"),
    ("vao_pp", dict(poisson_samples=False), "VAO++ with the spiral set instead of Poisson"),
    ("vao_pp", dict(filter=False), "VAO++ without the low-pass filter"),
    ("vao_pp", dict(samples=32), "VAO++, 32 samples"),
]


def grey(a):
    return np.repeat(a[..., None], 3, axis=2)


def save(name, strip, step=2):
    aolab.write_image(OUT / name, np.ascontiguousarray(strip[::step, ::step], dtype=np.float32))


def timed(method, g, **kw):
    aolab.compute(method, g, **kw)
    t0 = time.perf_counter()
    ao = aolab.compute(method, g, **kw)
    return ao, (time.perf_counter() - t0) * 1000


def room():
    g = aolab.load_gbuffer(ROOT / "reference_scenes" / "room" / "reference.exr")
    mask = g.valid_mask()
    radius = g.sidecar["ao_distance"]
    print("| variant | MAE | SSIM | bias | culled | mean samples | ms |")
    print("|---|---|---|---|---|---|---|")
    rows = []
    for method, settings, label in VARIANTS:
        ao, ms = timed(method, g, radius=radius, threads=2, **settings)
        m = aolab.metrics(ao, g.reference, mask)
        culled = samples = ""
        if method == "vao_pp":
            _, st = aolab.vao_pp_with_stats(g, radius=radius, threads=2, **settings)
            culled, samples = f"{100 * st['culled_share']:.1f} %", f"{st['mean_samples']:.1f}"
        print(f"| {label} | {m['mae']:.4f} | {m['ssim']:.4f} | {m['bias']:+.4f} | {culled} | "
              f"{samples} | {ms:.0f} |")
        err = np.where(mask, ao - g.reference, 0.0)
        rows.append(np.concatenate([grey(ao), signed_error_rgb(err, 0.5)], axis=1))
        if not settings:
            save(f"room_{method}.png",
                 np.concatenate([grey(g.reference), grey(ao), signed_error_rgb(err, 0.5)], axis=1))
    save("room_vao_variants.png", np.concatenate(rows[1:2] + rows[3:], axis=0), step=4)


def coloured_blocks():
    g0 = aolab.analytic_scene("blocks", 640, 360)
    n = g0.normal
    colour = np.clip(0.5 + 0.5 * n[..., [0, 1, 2]], 0, 1).astype(np.float32)  # by orientation
    colour[~g0.valid_mask()] = 0
    side = np.abs(n[..., 0]) > 0.7  # faces turned sideways glow
    emission = np.repeat(np.where(side, 3.0, 0.0)[..., None], 3, axis=2).astype(np.float32)
    g = aolab.GBuffer(g0.depth, g0.normal, colour, fx=g0.fx, fy=g0.fy, cx=g0.cx, cy=g0.cy,
                      emission=emission)
    ao = aolab.compute("vao_pp", g, radius=0.5)
    rgb = aolab.compute("vao_pp", g, radius=0.5, color_bleeding=True)
    save("blocks_vao_pp_bleeding.png", np.concatenate([grey(ao), rgb, colour], axis=1), step=1)
    lum = aolab.compute("vao_pp", g, radius=0.5, luminance_sensitivity=True)
    save("blocks_vao_pp_luminance.png",
         np.concatenate([grey(ao), grey(lum), np.clip(colour + emission, 0, 1)], axis=1), step=1)
    diff = np.abs(rgb - ao[..., None])
    print(f"\nblocks 640x360 R 0.5: bleeding |A·B - A| mean {diff.mean():.4f} "
          f"max {diff.max():.4f}; "
          f"luminance: AO mean {ao[side].mean():.4f} -> {lum[side].mean():.4f} on glowing faces, "
          f"{ao[~side].mean():.4f} -> {lum[~side].mean():.4f} elsewhere")


def coloured_room():
    """Colour bleeding and luminance sensitivity on the colored_room reference, whose G-buffer
    has Cycles' DiffCol and Emit passes (scripts/update_references.sh colored_room)."""
    g = aolab.load_gbuffer(ROOT / "reference_scenes" / "colored_room" / "reference.exr")
    if g.color is None or g.emission is None:
        print("colored_room has no DiffCol/Emit passes: re-render it first")
        return
    radius, mask = g.sidecar["ao_distance"], g.valid_mask()
    ao = aolab.compute("vao_pp", g, radius=radius)
    rgb = aolab.compute("vao_pp", g, radius=radius, color_bleeding=True)
    lum = aolab.compute("vao_pp", g, radius=radius, luminance_sensitivity=True)
    albedo = np.clip(g.color, 0, 1)
    save("colored_room_vao_pp_bleeding.png", np.concatenate([grey(ao), rgb, albedo], axis=1))
    glow = np.clip(g.color + g.emission, 0, 1)
    save("colored_room_vao_pp_luminance.png", np.concatenate([grey(ao), grey(lum), glow], axis=1))
    emitter = mask & (g.emission.max(axis=2) > 0)
    m_ao, m_lum = aolab.metrics(ao, g.reference, mask), aolab.metrics(lum, g.reference, mask)
    diff = np.abs(rgb - ao[..., None])[mask]
    print(f"\ncolored_room R {radius}: emitter pixels {emitter.sum()}, mean A there "
          f"{ao[emitter].mean():.4f} -> {lum[emitter].mean():.4f} with luminance sensitivity "
          f"(Cycles {g.reference[emitter].mean():.4f}); elsewhere {ao[mask & ~emitter].mean():.4f}"
          f" -> {lum[mask & ~emitter].mean():.4f}; MAE {m_ao['mae']:.4f} -> {m_lum['mae']:.4f}; "
          f"bleeding |A·B - A| mean {diff.mean():.4f} max {diff.max():.4f}")


if __name__ == "__main__":
    OUT.mkdir(parents=True, exist_ok=True)
    import sys
    if "--skip-room" not in sys.argv:
        room()
    coloured_blocks()
    coloured_room()
