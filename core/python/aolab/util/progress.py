"""The one progress bar every long run shows on stderr: tqdm's, or none where tqdm is missing
or the caller asked for none. Studies, renders and the advise command all take it from here,
so a bar looks and behaves the same wherever it appears."""
from __future__ import annotations

import sys


def bar(enabled: bool, total: int = 0, unit: str = "it", desc: str | None = None,
        leave: bool = True):
    """A tqdm bar on stderr of ``total`` ``unit``s (0: set later), or None when not
    ``enabled`` or without tqdm (python3-tqdm is optional: a run without it prints no bar)."""
    if not enabled:
        return None
    try:
        from tqdm import tqdm
    except ImportError:
        return None
    return tqdm(total=total, unit=unit, desc=desc, dynamic_ncols=True, leave=leave,
                file=sys.stderr)
