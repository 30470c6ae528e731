"""The counting half of scripts/sample_counts.sh: each run in a child process (gcov writes its
counters when a process exits), its counters read with gcov -t, then cleared.

    sample_counts.py BUILD_DIR HBAO_SOURCE_DIR [SCENE ...]
"""

import re
import subprocess
import sys
from pathlib import Path

# Each kernel's phases, in its order: a line of the function that runs once per sample
# (scalar code, hbao.cpp) or per vector of samples (SIMD kernel, hbao_simd.cpp) reaching the
# phase, as (the line's code, which occurrence of it after the function's first line). The
# lines are ones the optimiser leaves a whole count on: a line whose code moved elsewhere has
# none (the script stops naming it), and one whose code is shared with other lines (the
# horizon update's) can count more than once, so neither is used. The first phase is the
# samples or vectors given; the exact tangent test is the dear part.
FUNNELS = {
    "simd": ("hbao_simd.cpp", "HWY_INLINE void SampleStep(", {
        "given": ("const VF qy = hn::ConvertTo(df, hn::Sub(sy, hn::Set(di, k.y)));", 1),
        "past the prefilter": ("if (hn::AllFalse(df, live)) return;", 2),
        "in R: exact test": ("if (s.per_sample_tangent) {", 2),
        "counted": ("if (s.integral == int(HbaoIntegral::Cosine)) {  // cosine_gain", 1),
    }),
    "scalar": ("hbao.cpp", "bool per_sample_candidate(", {
        "given": ("const float qx = float(sx - p.x), qy = float(sy - p.y);", 1),
        "in R: sign test": ("counts = per_sample_candidate(p, qx, qy, ds, dd, r2, out);", 1),
        "past the sign test: exact test": ("const float grazing_s = rs_len / std::abs(n_rs);", 1),
        "counted": ("out.r = std::sqrt(r2);", 1),
    }),
}
RUN = """
import sys
from pathlib import Path
import numpy as np
import aolab
from aolab import scenes
folder = scenes.resolve_scenes([sys.argv[1]], Path(sys.argv[4]))[0]
g, _ref, radius, _crop = scenes.load_cropped(folder)
if (g.width, g.height) == (1280, 720):
    r = radius if sys.argv[2] == "own" else scenes.radius_for_pixels(g, float(sys.argv[2]))
    aolab.compute("hbao", g, radius=r, threads=1, preset="medium", blur=False, kernel=sys.argv[3])
print(int(np.asarray(g.valid_mask(), bool).sum()), g.width, g.height)
"""
LINE = re.compile(r"^\s*([0-9#=-]+)\*?:\s*(\d+):(.*)$")


def line_numbers(source: Path, anchor: str, phases: dict) -> dict[str, int]:
    """The source line of each phase's marker."""
    lines = [line.strip() for line in source.read_text().splitlines()]
    first = next(i for i, line in enumerate(lines) if line.startswith(anchor))
    out = {}
    for phase, (code, nth) in phases.items():
        hits = [i + 1 for i in range(first, len(lines)) if lines[i] == code]
        if len(hits) < nth:
            raise SystemExit(f"sample_counts: {source.name} has no line {code!r} (#{nth})")
        out[phase] = hits[nth - 1]
    return out


def line_counts(build: Path, source: Path, numbers: dict[str, int]) -> dict[str, int]:
    """gcov's count of each phase's line (summed where a line is compiled more than once, as
    Highway compiles the kernel once per instruction set; only one of them runs)."""
    gcda = next(build.rglob(source.name + ".gcda"))
    # gcov finds the notes file from the data file's name (CMake keeps the .cpp in both).
    text = subprocess.run(["gcov", "-t", str(gcda)], capture_output=True, text=True,
                          check=True, cwd=build).stdout
    counts, mine = {}, False
    for line in text.splitlines():
        m = LINE.match(line)
        if not m:
            continue
        if m.group(2) == "0":
            if m.group(3).startswith("Source:"):
                mine = m.group(3).endswith("/" + source.name)
            continue
        for phase, number in numbers.items():
            if mine and int(m.group(2)) == number and m.group(1) != "-":
                value = 0 if m.group(1).startswith(("#", "=")) else int(m.group(1))
                counts[phase] = counts.get(phase, 0) + value
    missing = set(numbers) - set(counts)
    if missing:
        raise SystemExit(f"sample_counts: gcov has no count on the lines of {sorted(missing)} "
                         f"in {source}")
    return counts


def run(build: Path, scene: str, radius: str, kernel: str, scenes_dir: Path) -> list[int]:
    for gcda in build.rglob("*.gcda"):
        gcda.unlink()
    out = subprocess.run([sys.executable, "-c", RUN, scene, radius, kernel, str(scenes_dir)],
                         capture_output=True, text=True, check=True).stdout
    return [int(v) for v in out.split()]


def main() -> int:
    build, sources = Path(sys.argv[1]), Path(sys.argv[2])
    scenes_dir = sources.parents[2] / "reference_scenes"
    names = sys.argv[3:] or sorted(d.name for d in scenes_dir.iterdir()
                                   if (d / "reference.exr").exists())
    for kernel, (source, anchor, phases) in FUNNELS.items():
        numbers = line_numbers(sources / source, anchor, phases)
        unit = "vectors" if kernel == "simd" else "samples"
        later = list(phases)[1:]
        print(f"\n## HBAO medium, {kernel} code, 1 thread: {unit} reaching each phase\n")
        print(f"| scene | radius | pixels with geometry | {unit} given per geometry pixel | "
              + " | ".join(later) + " |")
        print("|---" * (4 + len(later)) + "|")
        for name in names:
            for radius in ("own", "256"):
                geometry, width, height = run(build, name, radius, kernel, scenes_dir)
                if (width, height) != (1280, 720):
                    break
                c = line_counts(build, sources / source, numbers)
                shares = " | ".join(f"{100 * c[p] / c['given']:.1f} %" for p in later)
                label = "its R" if radius == "own" else "256 px"
                print(f"| {name} | {label} | {100 * geometry / (width * height):.0f} % | "
                      f"{c['given'] / geometry:.2f} | {shares} |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
