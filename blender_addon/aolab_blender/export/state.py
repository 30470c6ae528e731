"""Changing Blender settings for a render and putting every one of them back (bpy).

Every property the bridge touches goes through SettingsRestorer.set, which records the
original value the first time; restore() writes them back in reverse order and then undoes
what was created (a temporary world). reference.py (render_session, which peers.py uses
too) and mesh.py hold it as a context manager, so the user's scene is restored after
success, failure and cancellation alike.
"""

from __future__ import annotations


class SettingsRestorer:
    def __init__(self):
        self._saved = []       # (owner, attribute, original value), in order of first change
        self._seen = set()
        self._cleanups = []    # callables, run after the attributes are restored

    def set(self, owner, attr: str, value) -> None:
        """setattr(owner, attr, value), remembering the original value."""
        # RNA structs are keyed by their C pointer (wrappers are recreated on every access);
        # collections such as render_slots have none, and are set once each.
        key = (owner.as_pointer() if hasattr(owner, "as_pointer") else id(owner), attr)
        if key not in self._seen:
            self._seen.add(key)
            self._saved.append((owner, attr, getattr(owner, attr)))
        setattr(owner, attr, value)

    def on_restore(self, cleanup) -> None:
        """Registers a callable that undoes a creation (run after attributes are restored)."""
        self._cleanups.append(cleanup)

    def restore(self) -> None:
        errors = []
        for owner, attr, value in reversed(self._saved):
            try:
                setattr(owner, attr, value)
            except Exception as e:  # keep restoring the rest; report all at the end
                errors.append(f"{owner!r}.{attr}: {e}")
        for cleanup in reversed(self._cleanups):
            try:
                cleanup()
            except Exception as e:
                errors.append(f"cleanup {cleanup!r}: {e}")
        self._saved.clear()
        self._seen.clear()
        self._cleanups.clear()
        if errors:
            raise RuntimeError("could not restore every setting: " + "; ".join(errors))

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.restore()
        return False
