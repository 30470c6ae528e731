"""The hooks the properties' update= callbacks call (no bpy, nothing of the add-on).

properties.py's callbacks call `call(name, owner, context)`; live.py registers its functions
under these names when the add-on is registered, and removes them when it is unregistered.
So the properties reach Live without importing it (live.py imports properties.py), and a
callback with no hook registered does nothing. Blender calls update= callbacks on the main
thread, so the hooks run there.
"""

from __future__ import annotations

from typing import Callable

#: The hooks, each called with (the property group that changed, the context).
NAMES = ("live_toggled",            # window_manager.aolab.live
         "setting_changed",         # a method's setting, preset, blur or checkbox
         "scene_setting_changed")   # R, Scene AO Distance, the Resolution

_registered: dict[str, Callable] = {}


def register(**callbacks: Callable) -> None:
    """Registers a function under each name of NAMES given, replacing the one there."""
    unknown = sorted(set(callbacks) - set(NAMES))
    if unknown:
        raise ValueError(f"unknown hooks {unknown}; hooks are {', '.join(NAMES)}")
    _registered.update(callbacks)


def unregister() -> None:
    """Removes every hook: the callbacks do nothing until the next register()."""
    _registered.clear()


def call(name: str, owner, context) -> None:
    """Calls the function registered under `name` with (owner, context), if any."""
    if name not in NAMES:
        raise ValueError(f"unknown hook {name!r}; hooks are {', '.join(NAMES)}")
    fn = _registered.get(name)
    if fn is not None:
        fn(owner, context)
