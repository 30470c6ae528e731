"""Adapter to the comparison study (`aolab.presets`, `aolab.compare`; no bpy).

The presets and the HTML report come from the study's modules when this build has them;
otherwise the panel offers the method defaults only and the report button says
UNAVAILABLE. Every use of the study's API is in this file (docs/blender_addon.md lists the
signatures it assumes).
"""

from __future__ import annotations

from pathlib import Path

UNAVAILABLE = "comparison study not available in this build (aolab.compare missing)"
DEFAULT_PRESET = "default"   # the method's own defaults (always offered)


def _presets_module():
    try:
        from aolab import presets
        return presets
    except ImportError:
        return None


def _compare_module():
    try:
        from aolab import compare
        return compare
    except ImportError:
        return None


def preset_names(method: str) -> list[str]:
    """The method's presets, cheapest first (empty without aolab.presets or an entry)."""
    presets = _presets_module()
    if presets is None:
        return []
    e = presets.entry(method)
    if e is None:
        return []
    return [p for p in presets.PRESET_ORDER if p in e.presets]


def preset_values(method: str, name: str) -> tuple[dict, bool]:
    """(the method's settings, shared blur on/off) of a preset; the method's builtin blur
    switch is turned off when the shared blur replaces it, as the study does."""
    presets = _presets_module()
    e = presets.entry(method) if presets is not None else None
    if e is None or name not in e.presets:
        return {}, False
    values = dict(e.presets[name])
    blur = bool(values.pop("blur", False))
    if e.builtin_blur is not None and blur:
        values[e.builtin_blur] = False
    return values, blur


def report_available() -> bool:
    return _compare_module() is not None


def write_report(reference_folder: Path, methods: list[str], out: Path, threads: int) -> Path:
    """Runs the comparison study on one scene (the folder of its reference.exr) for
    `methods`, writes out/report.html (+ results.csv, results.json) and returns its path."""
    compare = _compare_module()
    if compare is None:
        raise RuntimeError(UNAVAILABLE)
    opts = compare.Options(scenes=[str(reference_folder)], methods=list(methods) or None,
                           out=Path(out), threads=threads, progress=False)
    compare.Study(opts).run()
    return Path(out) / "report.html"
