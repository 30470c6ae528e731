"""Inside Blender: the add-on's package from the checkout, with `aolab` made unimportable (as
when it is not built, or built for another Python), loads, registers, says "module not built"
in its panel and its operators, and unregisters: library.py is its one guarded door to
aolab, and nothing it imports when loaded imports aolab otherwise. Prints one JSON line
`RESULT {...}`.

    not_built_check.py
"""
import importlib.abc
import json
import os
import sys
from types import SimpleNamespace

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import ROOT, Layout, call  # noqa: E402


class HideAolab(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name == "aolab" or name.startswith("aolab."):
            raise ModuleNotFoundError(f"No module named {name!r} (hidden by the test)")
        return None


sys.meta_path.insert(0, HideAolab())
sys.path.insert(0, os.path.join(ROOT, "blender_addon"))

import bpy  # noqa: E402

import aolab_blender  # noqa: E402
from aolab_blender import library, ui  # noqa: E402

aolab_blender.register()
c = bpy.context
texts = []
ui.draw_panel(Layout(texts), SimpleNamespace(scene=c.scene, window_manager=c.window_manager,
                                             region=None, preferences=c.preferences))
r = {"file": aolab_blender.__file__, "available": library.available(),
     "import_error": library.IMPORT_ERROR, "not_built": library.NOT_BUILT,
     "panel": texts, "preview": call(bpy.ops.aolab.preview),
     "aolab_modules": sorted(n for n in sys.modules if n == "aolab" or n.startswith("aolab."))}
aolab_blender.unregister()
r["unregistered"] = not hasattr(bpy.types.WindowManager, "aolab")
print("RESULT " + json.dumps(r))
