#!/usr/bin/python3
"""Images for docs/methods/: each method (default settings, the scene's R) on committed
reference scenes, beside the Cycles reference and the signed error (red = too dark,
blue = too light), with the scores. Run after scripts/build.sh:

    PYTHONPATH=build/python /usr/bin/python3 scripts/doc_images.py [scene ...]

Writes docs/images/<scene>_<method>.png and prints a Markdown table of the scores.
"""
import sys
from pathlib import Path

import numpy as np

import aolab
from aolab.scoring import signed_error_rgb

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "images"


def grey(a):
    return np.repeat(a[..., None], 3, axis=2)


def main(scenes):
    OUT.mkdir(parents=True, exist_ok=True)
    print("| scene | method | MAE | SSIM | bias | ms |")
    print("|---|---|---|---|---|---|")
    for scene in scenes:
        g = aolab.load_gbuffer(ROOT / "reference_scenes" / scene / "reference.exr")
        mask = g.valid_mask()
        radius = g.sidecar["ao_distance"]
        for method in aolab.methods():
            import time
            aolab.compute(method, g, radius=radius)  # warm-up
            t0 = time.perf_counter()
            ao = aolab.compute(method, g, radius=radius)
            ms = (time.perf_counter() - t0) * 1000
            m = aolab.metrics(ao, g.reference, mask)
            err = np.where(mask, ao - g.reference, 0.0)
            strip = np.concatenate([grey(g.reference), grey(ao), signed_error_rgb(err, 0.5)],
                                   axis=1)
            aolab.write_image(OUT / f"{scene}_{method}.png",
                              np.ascontiguousarray(strip[::2, ::2], dtype=np.float32))
            print(f"| {scene} | {method} | {m['mae']:.4f} | {m['ssim']:.4f} | "
                  f"{m['bias']:+.4f} | {ms:.0f} |")


if __name__ == "__main__":
    main(sys.argv[1:] or ["room", "grille"])
