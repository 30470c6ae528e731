"""``aolab bench-table``: every method's scalar code against its SIMD kernel, in one run.

Per method, at a preset (``medium`` by default, ``default`` for a method without it; the
shared blur left out as the study times it apart) on the ``blocks`` analytic scene at
1280×720 with R = 0.25 (the benchmarks' scene, docs/benchmarks.md):

- ``scalar ms``: the scalar per-pixel code (``kernel="scalar"``) on 1 thread — the plain
  implementation of the algorithm, and the SIMD kernel's test oracle;
- ``simd 1t`` and ``simd 2t``: the SIMD kernel on 1 and 2 threads;
- ``speed-up``: scalar ms / simd 2t;
- ``2t/1t``: simd 1t / simd 2t, how well the second core serves;
- ``Mpx/s`` and ``Msamples/s`` at 2 threads, where the method's samples per pixel are a
  count of its settings (``samples_per_pixel``);
- with ``scaling``: the SIMD kernel at 3840×2160 on 2 threads, its ratio to 1280×720 (9 for
  time linear in the pixels), the same at R/3 (which projects to as many pixels there as R
  at 1280×720, so each pixel's work and neighbourhood are unchanged), and the peak memory of
  one run there, measured in a child process (its peak resident size less the size before
  the run);
- with ``radii``: the SIMD kernel on 2 threads at R × 2, 4 and 8 (the preset's settings
  unchanged, so the samples per pixel stay fixed and each method's own cost growth shows),
  and the ratio ×8 / ×1.

A last row times the shared separable Gaussian (``blur=True`` in a preset) alone, on the same
frame. Times are medians of ``repeat`` runs after one warm-up, wall clock. ``profile`` also
records each method's SIMD kernel with Linux ``perf`` and prints its hottest functions.
"""

from __future__ import annotations

import json
import os
import platform
import shutil
import subprocess
import sys
from pathlib import Path

import aolab

from .. import catalog
from .. import named_presets as presets_module
from ..util import files
from ..study.runner import median_ms
from ..util.provenance import git_commit

#: The benchmarks' scene and radius (docs/benchmarks.md; tests/bench/bench_scene.h).
SCENE = "blocks"
RADIUS = 0.25
SIZE = (1280, 720)
LARGE_SIZE = (3840, 2160)
#: The radius multiples of the ``radii`` columns.
RADIUS_SCALES = (2, 4, 8)
#: The name of the blur's row.
BLUR_ROW = "shared blur"


def samples_per_pixel(method: str, settings: dict) -> float | None:
    """Depth reads per pixel that the method's settings fix (its catalog entry's rule; None
    where they do not: the line sweeps' and Chebyshev's cost is per line and per kernel,
    Pyramid HBAO's depends on the levels R spans)."""
    entry = catalog.entry(method)
    if entry is None or entry.samples_per_pixel is None:
        return None
    full = {s["name"]: s["default"] for s in aolab.method_info(method)["settings"]}
    full.update(settings)
    return entry.samples_per_pixel(full)


def compute_ms(method, g, settings, *, threads, kernel, repeat, radius=RADIUS) -> float:
    """The median ms of ``method`` on ``g`` with ``kernel`` (runner.median_ms: one warm-up
    for first-touch page faults, caches and the dispatch table, then ``repeat`` timed)."""
    return median_ms(lambda: aolab.compute(method, g, radius=radius, threads=threads,
                                           kernel=kernel, **settings), repeat)


#: The preset timed when none is asked for, where the method has it.
DEFAULT_BENCH_PRESET = "medium"


def bench_preset(method: str, preset: str | None) -> str:
    """The preset timed for ``method``: ``preset``, checked as ``aolab.compute(preset=...)``
    checks it (an unknown method or name is a ValueError listing what there is), or when
    None DEFAULT_BENCH_PRESET, else the method's own defaults (a bound such as
    screen_space_limit has no presets: its row says "default", not a name it lacks)."""
    if preset is None:
        has = DEFAULT_BENCH_PRESET in presets_module.preset_names(method)
        preset = DEFAULT_BENCH_PRESET if has else presets_module.DEFAULT_PRESET
    presets_module.settings_of(method, preset)
    return preset


def configuration(method: str, preset: str) -> dict:
    """The preset's own settings as the study runs them (no blur)."""
    values, _blur = presets_module.preset_values(method, preset)
    return values


def peak_memory_mb(method: str, settings: dict, size=LARGE_SIZE) -> float:
    """Peak resident memory of one run of the SIMD kernel at ``size`` beyond what the process
    held before it (the G-buffer included there), in MiB, from a child process: Linux's peak
    resident size (VmHWM) is reset just before the run (``/proc/self/clear_refs``), so the
    G-buffer's own making does not hide the run's peak. It is the first run of the process, so
    no memory the allocator kept from an earlier run hides part of it either."""
    code = (
        "import json, sys, aolab\n"
        "def kib(field):\n"
        "    for line in open('/proc/self/status'):\n"
        "        if line.startswith(field + ':'):\n"
        "            return int(line.split()[1])\n"
        "m, s, w, h, r = json.loads(sys.argv[1])\n"
        "g = aolab.analytic_scene('blocks', w, h)\n"
        "before = kib('VmRSS')\n"
        "open('/proc/self/clear_refs', 'w').write('5')\n"
        "ao = aolab.compute(m, g, radius=r, threads=2, **s)\n"
        "print((kib('VmHWM') - before) / 1024.0)\n")
    arg = json.dumps([method, settings, size[0], size[1], RADIUS])
    out = subprocess.run([sys.executable, "-c", code, arg], capture_output=True, text=True,
                         check=True, env=dict(os.environ))
    return float(out.stdout.strip().splitlines()[-1])


def default_methods() -> list[str]:
    """Every method but the bounds."""
    return [m for m in aolab.methods() if not aolab.method_info(m)["bound"]]


def table(methods=None, *, preset: str | None = None, repeat: int = 5, scaling: bool = False,
          radii: bool = False, size=SIZE, blur: bool = True, progress=print) -> list[dict]:
    """One row per method (see the module docstring) at ``preset`` (:func:`bench_preset`);
    bounds are left out unless named. ``blur`` adds the shared blur's row (method
    ``BLUR_ROW``: no scalar/SIMD split, its time in every column). Every method and preset
    is checked before the first timing."""
    methods = methods or default_methods()
    chosen = {m: bench_preset(m, preset) for m in methods}
    g = aolab.analytic_scene(SCENE, *size)
    large = aolab.analytic_scene(SCENE, *LARGE_SIZE) if scaling else None
    pixels = size[0] * size[1]
    rows = []
    for method in methods:
        settings = configuration(method, chosen[method])
        has_simd = aolab.method_info(method)["simd_kernel"]
        scalar = compute_ms(method, g, settings, threads=1, kernel="scalar",
                            repeat=max(1, min(repeat, 3)))
        simd1 = compute_ms(method, g, settings, threads=1, kernel="simd", repeat=repeat)
        simd2 = compute_ms(method, g, settings, threads=2, kernel="simd", repeat=repeat)
        spp = samples_per_pixel(method, settings)
        row = {"method": method, "preset": chosen[method], "settings": settings, "size": list(size),
               "simd_kernel": has_simd, "scalar_ms": scalar, "simd_1t_ms": simd1,
               "simd_2t_ms": simd2, "speedup": scalar / simd2, "threads_ratio": simd1 / simd2,
               "mpx_per_s": pixels / simd2 / 1000.0,
               "msamples_per_s": None if spp is None else pixels * spp / simd2 / 1000.0}
        if scaling:
            big = compute_ms(method, large, settings, threads=2, kernel="simd",
                             repeat=max(1, min(repeat, 3)))
            row["large_ms"] = big
            row["large_ratio"] = big / simd2
            # R / 3 projects to as many pixels at 3840×2160 as R at 1280×720: the same work
            # and neighbourhood per pixel, so this ratio isolates the pixel count.
            scale = LARGE_SIZE[0] / size[0]
            same = compute_ms(method, large, settings, threads=2, kernel="simd",
                              repeat=max(1, min(repeat, 3)), radius=RADIUS / scale)
            row["large_same_px_ms"] = same
            row["large_same_px_ratio"] = same / simd2
            row["large_peak_mb"] = peak_memory_mb(method, settings)
        if radii:
            row["radius_ms"] = {str(k): compute_ms(method, g, settings, threads=2,
                                                   kernel="simd", repeat=max(1, min(repeat, 3)),
                                                   radius=RADIUS * k)
                                for k in RADIUS_SCALES}
            row["radius_ratio"] = row["radius_ms"][str(RADIUS_SCALES[-1])] / simd2
        rows.append(row)
        if progress:
            progress(format_row(row))
    if blur:
        # The blur's cost does not depend on the AO it smooths (the same taps over the same
        # geometry pixels), so any AO serves: HBAO's, at the preset every run of it has.
        ao = aolab.compute("hbao", g, radius=RADIUS, **configuration("hbao", "medium"))
        one, two = (median_ms(lambda t=t: aolab.gaussian_blur(ao, g, threads=t), repeat)
                    for t in (1, 2))
        row = {"method": BLUR_ROW, "preset": "σ 1.5, 5 taps", "settings": {}, "size": list(size),
               "simd_kernel": False, "scalar_ms": one, "simd_1t_ms": one, "simd_2t_ms": two,
               "speedup": one / two, "threads_ratio": one / two,
               "mpx_per_s": pixels / two / 1000.0, "msamples_per_s": None}
        if scaling or radii:   # not measured for the blur: empty cells keep the table square
            row["blank_cells"] = 5 * scaling + (len(RADIUS_SCALES) + 1) * radii
        rows.append(row)
        if progress:
            progress(format_row(row))
    return rows


HEADER = ("| method | preset | SIMD kernel | scalar 1t ms | SIMD 1t ms | SIMD 2t ms | speed-up "
          "| 2t/1t | Mpx/s | Msamples/s |")


def format_row(row: dict) -> str:
    samples = "—" if row["msamples_per_s"] is None else f"{row['msamples_per_s']:.0f}"
    text = (f"| {row['method']} | {row['preset']} | {'yes' if row['simd_kernel'] else 'no'} "
            f"| {row['scalar_ms']:.1f} | {row['simd_1t_ms']:.1f} | {row['simd_2t_ms']:.1f} "
            f"| {row['speedup']:.1f}× | {row['threads_ratio']:.2f} | {row['mpx_per_s']:.1f} "
            f"| {samples} |")
    if "large_ms" in row:
        text += (f" {row['large_ms']:.0f} | {row['large_ratio']:.1f} "
                 f"| {row['large_same_px_ms']:.0f} | {row['large_same_px_ratio']:.1f} "
                 f"| {row['large_peak_mb']:.0f} |")
    text += " |" * row.get("blank_cells", 0)
    if "radius_ms" in row:
        text += "".join(f" {row['radius_ms'][str(k)]:.1f} |" for k in RADIUS_SCALES)
        text += f" {row['radius_ratio']:.2f} |"
    return text


def header(scaling: bool, radii: bool = False) -> str:
    h = HEADER
    if scaling:
        h += (" SIMD 2t ms at 3840×2160 | ×(9 = linear) | at 3840×2160, R/3 | ×(9 = linear) "
              "| peak MiB at 3840×2160 |")
    if radii:
        h += "".join(f" R×{k} ms |" for k in RADIUS_SCALES)
        h += f" R×{RADIUS_SCALES[-1]} / R×1 |"
    return h + "\n" + "|---" * (h.count("|") - 1) + "|"


def machine() -> str:
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    return (f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
            f"load average {load:.2f} at the start")


def simd_target() -> str:
    """The instruction set Highway dispatches to on this machine (the kernels' best target)."""
    return aolab.simd_target() if hasattr(aolab, "simd_target") else "unknown"


def profile(method: str, settings: dict, folder: Path, *, size=SIZE, runs: int = 10,
            top: int = 12) -> list[str]:
    """Records ``runs`` computations of the method's SIMD kernel on 2 threads with ``perf
    record`` into folder/METHOD.perf.data, writes ``perf report`` to folder/METHOD.txt and
    returns its ``top`` hottest functions (self time)."""
    need_perf()
    folder.mkdir(parents=True, exist_ok=True)
    data, report = profile_files([method], folder)
    code = ("import json, sys, aolab\n"
            "m, s, w, h, r, n = json.loads(sys.argv[1])\n"
            "g = aolab.analytic_scene('blocks', w, h)\n"
            "for _ in range(n): aolab.compute(m, g, radius=r, threads=2, **s)\n")
    arg = json.dumps([method, settings, size[0], size[1], RADIUS, runs])
    subprocess.run(["perf", "record", "-q", "-o", str(data), "--", sys.executable, "-c", code,
                    arg], check=True, env=dict(os.environ), capture_output=True)
    out = subprocess.run(["perf", "report", "-i", str(data), "--stdio", "--no-children",
                          "--sort", "symbol", "--percent-limit", "0.5"],
                         capture_output=True, text=True, check=True).stdout
    files.write_text(report, out)
    lines = [line.rstrip() for line in out.splitlines()
             if line.strip() and not line.lstrip().startswith("#")]
    return lines[:top]


def profile_files(methods: list[str], folder) -> list[Path]:
    """The files :func:`profile` writes into ``folder`` for ``methods`` (none without one)."""
    return [Path(folder) / f"{m}{suffix}" for m in methods for suffix in (".perf.data", ".txt")
            if folder]


def need_perf() -> None:
    if shutil.which("perf") is None:
        raise ValueError("--profile needs Linux perf (Debian package linux-perf: "
                         "scripts/install-deps.sh installs it)")


def commit() -> str:
    return git_commit(Path(__file__).resolve().parent) or "unknown"
