"""The panel's one door to the `aolab` package: the only module of the add-on's panel that
imports it, guarded, so that the add-on loads, registers and says what is wrong without it.

- `aolab` is found through the .pth that scripts/setup.sh writes into Debian's site folder
  (Blender's Python reads it too), so the user never touches sys.path.
- When it does not import (missing, not built, or built for another Python than Blender's),
  every name below is None, `available()` is False and `problem()` is the one line the panel
  and the operators show (NOT_BUILT, what is wrong, the import error). The method groups of
  properties.py are then empty.
- export.scene_record imports `aolab` at the top (the headless export runs where it is), so
  it is imported here, guarded the same way, for the panel's reads of the scene.
The other modules take what they need from here (`library.jobs`, `library.presets`, ...),
read when called, so a name set to None (a test) is seen at once.
"""

import sys

try:
    import aolab
    from aolab import named_presets as presets
    from aolab import settings as method_settings
    from aolab.bridge import constants, intrinsics, passes
    from aolab.jobs import live as live_jobs
    from aolab.jobs import runner, tasks
    from aolab.cycles.cache import default_cache, find_by_content
    from aolab.study import advise, quick_reference

    from .export import scene_record
except ImportError as e:  # missing, not built, or built for another Python
    aolab = presets = method_settings = constants = intrinsics = passes = None
    live_jobs = runner = tasks = default_cache = find_by_content = None
    advise = quick_reference = scene_record = None
    IMPORT_ERROR = str(e)
    _MISSING = e.name
else:
    IMPORT_ERROR = _MISSING = None

NOT_BUILT = "module not built: run scripts/setup.sh"
#: The quick reference's rays and Advise's budgets (aolab.study's; the properties are made
#: even when aolab is missing, and then nothing uses them).
QUICK_RAYS = quick_reference.QUICK_RAYS if quick_reference is not None else 64
BUDGETS_MS = advise.BUDGETS_MS if advise is not None else (16, 33, 100)


def available() -> bool:
    """Whether the aolab package imported."""
    return aolab is not None


def problem() -> str | None:
    """Why the add-on cannot work, in one line: NOT_BUILT, what is wrong and the import
    error; None when aolab imported."""
    if available():
        return None
    python = "Blender's Python %d.%d" % sys.version_info[:2]
    if _MISSING == "aolab":
        why = f"the aolab package is not on the path of {python}"
    elif _MISSING is not None and _MISSING.startswith("aolab._core"):
        why = f"aolab's compiled module is missing (not built, or built for another " \
              f"Python than {python})"
    else:
        why = "aolab does not import"
    return f"{NOT_BUILT}: {why}" + (f" ({IMPORT_ERROR})" if IMPORT_ERROR else "")


def methods() -> list[str]:
    """aolab.methods(), or none when aolab is missing."""
    return list(aolab.methods()) if available() else []
