"""SHA-256 of every method's output on every committed reference scene, at its defaults and
at every preset, so that a refactor can show it changed no bit:

    PYTHONPATH=build/python /usr/bin/python3 tests/tools/output_digests.py > before.json
    ... refactor, rebuild ...
    PYTHONPATH=build/python /usr/bin/python3 tests/tools/output_digests.py > after.json
    diff before.json after.json        # no output: bit-identical

Each entry hashes the float32 bytes of the result (and of the shared blur after it, where the
preset asks for it), computed on 2 threads at the scene's R.
"""
import hashlib
import json
import sys
from pathlib import Path

import numpy as np

import aolab
from aolab import named_presets as presets

ROOT = Path(__file__).resolve().parents[2]


def digest(array) -> str:
    return hashlib.sha256(np.ascontiguousarray(array, dtype=np.float32).tobytes()).hexdigest()


def main() -> int:
    out = {}
    for folder in sorted((ROOT / "reference_scenes").iterdir()):
        exr = folder / "reference.exr"
        if not exr.exists():
            continue
        radius = json.loads((folder / "manifest.json").read_text())["radius"]
        g = aolab.load_gbuffer(exr)
        for method in aolab.methods():
            if aolab.method_info(method)["bound"]:
                continue  # a bound at hundreds of rays per pixel, minutes a scene: not refactored
            configs = [("default", {}, False)]
            configs += [(s.label, s.compute_settings(), s.blur)
                        for s in presets.settings_for(method, "presets")]
            for label, settings, blur in configs:
                ao = aolab.compute(method, g, radius=radius, threads=2, **settings)
                entry = digest(ao)
                if blur:
                    entry += " blur " + digest(aolab.gaussian_blur(ao, g))
                out[f"{folder.name} {method} {label}"] = entry
                print(folder.name, method, label, file=sys.stderr)
    json.dump(out, sys.stdout, indent=1, sort_keys=True)
    print()
    return 0


if __name__ == "__main__":
    sys.exit(main())
