"""What the study knows of each method, one module per method: its presets (``low`` <
``medium`` < ``high`` < ``ultra``) and the grid of its quality settings that the full sweep
covers, the bounds aolab tune searches its settings in, and the samples per pixel its
settings fix (``MethodEntry``, catalog/kinds.py). The radius is never set here: every method
runs with the scene's R. Settings not named keep the method's defaults.

Adding a method to the study is one file, ``catalog/<name>.py`` with its ``ENTRY``, and its
module in ``MODULES`` below (in the order of aolab.methods()). A method of aolab.methods()
without an entry runs once, at its defaults. The API reads the entries for
``aolab.presets``; the study (aolab.study) and aolab bench-table read them too."""

from __future__ import annotations

from . import (alchemy, bitmask, chebyshev, crytek_ssao, gtao, hbao, lsao, pyramid_hbao, sao,
               vao, vao_pp)
from .kinds import MethodEntry

MODULES = (hbao, pyramid_hbao, lsao, chebyshev, vao, vao_pp, gtao, bitmask, alchemy, sao,
           crytek_ssao)
#: Every method's entry by name.
ENTRIES: dict[str, MethodEntry] = {m.ENTRY.method: m.ENTRY for m in MODULES}


def entry(method: str) -> MethodEntry | None:
    """The entry of ``method``, or None for a method the study knows nothing of."""
    return ENTRIES.get(method)
