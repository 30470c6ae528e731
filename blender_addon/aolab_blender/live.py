"""Live preview: the panel's settings followed on the cached G-buffer, no button press (bpy).

With *Live* ticked (`window_manager.aolab.live`), every change of a method's setting, preset,
blur or checkbox, of R, of Scene AO Distance or of the Resolution calls `changed()` (an
`update=` callback, main thread): the methods it affects become dirty, their generation
goes up, and `tick` is registered with bpy.app.timers. `tick` (main thread, a timer) waits
until the changes have been quiet for DEBOUNCE_S (at most MAX_DEFER_S after the first), then
takes a snapshot of the latest settings of the dirty methods and hands it to the worker;
changes made meanwhile only mark methods dirty again, so any number of quick changes cost
one compute of the latest values each time the worker is free. The worker
(aolab.jobs.live.LiveWorker, no bpy: a runner.Job per snapshot, like the operators' jobs)
runs aolab.compute (C++, the GIL released) on the G-buffer kept in memory (loaded from the
cache's EXR once per folder). `tick` writes each finished result into its image, unless the
method's generation moved on meanwhile (the result is stale: dropped, and the newer change
has its own compute coming; a compute of a method that changes while it runs is cancelled
through its aolab.Progress, so a slow method does not finish a result nobody will see). The
timer ends (returns None) when nothing is dirty, computing or converging. This module keeps
only what touches bpy, and runs on the main thread alone.

While nothing changes, the image converges (`scene.aolab.live_frames`, "Accumulate", N > 1):
each method with a `seed` shown at frame 0 is computed again at frames k = 1 ... N-1
(aolab.compute(..., frame=k): a per-frame seed) and blended by the worker (aolab.accumulate
as a running mean: alpha 0, no clamp, zero motion, since the G-buffer is the same), one
frame per timer
call, the method furthest behind first; the image after frame k is the mean of frames 0..k.
Then the timer ends: no CPU once converged. Any change that redraws a method (its setting,
R, the Resolution, Accumulate, its checkbox) drops its history and starts again at frame 0;
so does a depsgraph change after which the G-buffer being accumulated is not the scene's
(checked before the next frame: the content hash once per change). Nothing accumulates
across a change, and with N = 1 Live is a single frame, as it was before.

The G-buffer is the one Preview uses: a cached render of this scene content at the
Resolution. Live never exports one (that takes a Blender render): without it the panel says
so and names the Preview button, and nothing is computed. The scene's content hash
(inputs.scene_hash, which reads every mesh) is computed at most once per scene, camera and
size, and again only after the depsgraph reported a change to something other than the
scene's own properties or an image.
"""

from __future__ import annotations

import time
from pathlib import Path

import bpy

from . import hooks, images, library, properties
from .inputs import UserError, find_reference, scene_hash, scene_inputs

#: Changes closer together than this are coalesced into one compute (a preset sets every
#: setting of its method; a dragged slider sends a change per mouse move).
DEBOUNCE_S = 0.015
#: ... but a compute starts at the latest this long after the first pending change, so that
#: a slider dragged without a pause still redraws.
MAX_DEFER_S = 0.05
#: The timer's interval while a compute runs (its result is shown at most this late).
POLL_S = 0.005
#: How long unregister() waits for a running compute (the worker holds no Blender data).
JOIN_S = 2.0
#: Only IDs whose change may alter the G-buffer (geometry, transforms, camera, materials).
#: A Scene update is the panel's own properties; an Image one is Live writing its result.
_IGNORED_UPDATES = (bpy.types.Scene, bpy.types.Image, bpy.types.WindowManager,
                    bpy.types.Screen, bpy.types.WorkSpace, bpy.types.Text)
ALL = "*"   # changed(ALL): every ticked method (R, Resolution)


class _State:
    def __init__(self):
        self.dirty: set[str] = set()
        self.generation: dict[str, int] = {}   # method -> changes so far
        self.changed_at: dict[str, float] = {}  # method -> perf_counter of its latest change
        self.first_pending = 0.0                # perf_counter of the oldest undone change
        self.last_change = 0.0
        self.worker = None                      # aolab.jobs.live.LiveWorker, made when used
        self.hashes: dict[tuple, str] = {}      # (scene, camera, size) -> content hash
        self.folders: dict[tuple, Path] = {}    # (hash, size, passes, cache) -> G-buffer
        self.radius: float | None = None        # R of the last snapshot (world changes)
        self.stats = {"computes": 0, "applied": 0, "dropped": 0, "cancelled": 0,
                      "snapshots": 0, "frames": 0}   # frames: accumulation frames k >= 1
        self.accum: dict[str, dict] = {}        # method -> its converging run (_next_frame)
        self.recheck = False                    # the scene changed while converging
        self.last: list[dict] = []              # the last applied updates (tests, timing)
        self.closed = False


_state = _State()


# ---- main thread: changes ----

def changed(context, method: str = ALL) -> None:
    """An `update=` callback's work: marks `method` (or every method) dirty and makes sure
    the timer runs. Cheap: Blender calls it on every step of a dragged slider."""
    session = context.window_manager.aolab
    if not session.live or _state.closed:
        return
    now = time.perf_counter()
    names = library.methods() if method == ALL else [method]
    for m in names:
        _state.generation[m] = _state.generation.get(m, 0) + 1
        _state.changed_at[m] = now
    _cancel_running(names)
    for m in names:   # nothing accumulates across a change
        _state.accum.pop(m, None)
    if not _state.dirty:
        _state.first_pending = now
    _state.dirty.update(names or [ALL])   # no method (not built): the snapshot says why
    _state.last_change = now
    if not bpy.app.timers.is_registered(tick):
        bpy.app.timers.register(tick, first_interval=DEBOUNCE_S)


def _cancel_running(methods) -> None:
    """A compute of a method that changed is stale: stopped, so that the latest values
    start sooner (a slow method would otherwise finish a result nobody sees)."""
    if _state.worker is not None:
        _state.worker.cancel(methods)


def on_toggle(session, context) -> None:
    """Live switched on: everything ticked is computed (and the G-buffer looked up); off:
    pending changes are forgotten, a running compute's result is dropped."""
    if session.live:
        session.live_message, session.live_message_is_error = "waiting for the first update", False
        session.live_method = ""   # the times shown are this run's
        changed(context)
    else:
        _forget_pending()
        session.live_message = ""


def on_setting(group, context) -> None:
    """update= of a method group's settings, blur and checkbox."""
    changed(context, group.method_name)


def on_scene_setting(group, context) -> None:
    """update= of R, Scene AO Distance and the Resolution: every method."""
    changed(context)


def gbuffer_exported(context) -> None:
    """Preview has exported (or found) the G-buffer: the next lookup sees it."""
    _state.folders.clear()
    session = context.window_manager.aolab
    if session.live and session.live_message_is_error:
        changed(context)


def _forget_pending() -> None:
    for m in list(_state.generation):   # a running compute's results become stale
        _state.generation[m] += 1
    _cancel_running(list(_state.generation))
    _state.dirty.clear()
    _state.accum.clear()


def _on_depsgraph(scene, depsgraph) -> None:
    """Anything but the panel's properties or an image changed: the content hash must be
    computed again before the next compute. A world change may be a new AO distance."""
    ids = [u.id for u in depsgraph.updates]
    if any(not isinstance(i, _IGNORED_UPDATES) for i in ids):
        _state.hashes.clear()
        _state.recheck = bool(_state.accum)   # tick: is the G-buffer still this scene's?
    if any(isinstance(i, bpy.types.World) for i in ids):
        context = bpy.context
        session = context.window_manager.aolab
        if session.live and properties.effective_radius(context.scene) != _state.radius:
            changed(context)


def _on_load(*_args) -> None:
    """A file is being loaded: its scenes are others; the timers are removed by Blender."""
    _forget_pending()
    _state.hashes.clear()
    _state.folders.clear()
    _state.radius = None
    if _state.worker is not None:
        _state.worker.gbuffers.clear()


# ---- main thread: the timer ----

def tick() -> float | None:
    """bpy.app.timers callback: shows finished results, starts the next compute when the
    changes are quiet, or else the next accumulation frame. Returns the seconds to the next
    call, None when nothing is left."""
    if _state.closed:
        return None
    context = bpy.context
    # Whether the worker ended is read before its results are taken: a frame that ended in
    # between is shown now, never computed twice.
    running = _state.worker is not None and _state.worker.busy()
    _apply_results(context)
    if not _state.dirty:
        if not running and _state.accum:
            _next_frame(context)
            running = computing()
        return POLL_S if running or _state.dirty else None
    if running:
        return POLL_S
    now = time.perf_counter()
    wait = min(_state.last_change + DEBOUNCE_S, _state.first_pending + MAX_DEFER_S) - now
    if wait > 0:
        return wait
    _start(context)   # may compute nothing (an unticked method): the others converge on
    return POLL_S if computing() or _state.accum else None


def computing() -> bool:
    """Whether a compute was started whose end the timer has not seen yet."""
    return _state.worker is not None and _state.worker.job is not None


def _scene_hash(context, scene, size) -> str:
    context.evaluated_depsgraph_get()   # pending depsgraph updates reach _on_depsgraph first
    key = (scene.name, scene.camera.name, tuple(size))
    h = _state.hashes.get(key)
    if h is None:
        h = _state.hashes[key] = scene_hash(scene, size)
    return h


def _find_gbuffer(inputs: dict) -> Path | None:
    """inputs.find_reference's G-buffer (any render of this content and size), the
    folder remembered: the lookup reads every sidecar of the cache."""
    key = (inputs["scene_hash"], tuple(inputs["size"]), tuple(inputs["passes"]),
           str(inputs["cache"]))
    folder = _state.folders.get(key)
    if folder is None or not (folder / library.constants.RESULT_EXR).exists():
        folder = find_reference(inputs, spp=None)
        if folder is not None:
            _state.folders[key] = folder
    return folder


def _lookup(context) -> tuple[dict, Path | None]:
    """The scene's inputs read now and the folder of its cached G-buffer (None: not
    cached). UserError when the scene cannot be exported."""
    inputs = scene_inputs(context, need_runs=False, hash_scene=False)
    inputs["scene_hash"] = _scene_hash(context, context.scene, inputs["size"])
    return inputs, _find_gbuffer(inputs)


def _gbuffer_exr(context) -> str | None:
    """The cached G-buffer of the scene as it is now (None: none, or the scene cannot be
    exported)."""
    try:
        _, folder = _lookup(context)
    except UserError:
        return None
    return None if folder is None else str(Path(folder) / library.constants.RESULT_EXR)


def _next_frame(context) -> None:
    """Starts the next accumulation frame of the converging method furthest behind; first,
    after a depsgraph change, restarts every method if the G-buffer is not the scene's now
    (a moved object: the snapshot then says that Preview must export it)."""
    if _state.recheck:
        _state.recheck = False
        exrs = {a["plan"]["exr"] for a in _state.accum.values()}
        if exrs != {_gbuffer_exr(context)}:
            changed(context)
            return
    order = {m: i for i, m in enumerate(library.methods())}
    method = min(_state.accum, key=lambda m: (_state.accum[m]["frame"], order.get(m, 0)))
    entry = _state.accum[method]
    run = {**entry["run"], "frame": entry["frame"], "changed_at": time.perf_counter()}
    _start_worker({**entry["plan"], "runs": [run], "snapshot_s": 0.0})
    _state.stats["frames"] += 1


def snapshot(context) -> dict | None:
    """What the worker needs, read from Blender now: the G-buffer folder, R, threads and the
    dirty methods' latest runs with their generations. None (and the panel's message set)
    when nothing can be computed. Clears the dirty set."""
    session = context.window_manager.aolab
    scene = context.scene
    dirty, _state.dirty = _state.dirty, set()
    _state.stats["snapshots"] += 1
    try:
        inputs, folder = _lookup(context)
    except UserError as e:
        _set_message(session, str(e), error=True)
        return None
    w, h = inputs["size"]
    if folder is None:
        _set_message(session, f"no G-buffer of this scene at {w}x{h} is cached: click "
                     "Preview once to export it, then changes show live", error=True)
        return None
    _state.radius = inputs["radius"]
    runs = [r for r in inputs["runs"] if r["method"] in dirty]
    ticked = {r["method"] for r in inputs["runs"]}
    _drop_rows(session, [m for m in dirty if m not in ticked])
    if not runs:
        _set_message(session, "nothing ticked to preview" if not ticked else
                     session.live_message, error=False)
        return None
    frames = scene.aolab.live_frames
    for r in runs:
        r["generation"] = _state.generation.get(r["method"], 0)
        r["changed_at"] = _state.changed_at.get(r["method"], time.perf_counter())
        # A method without a seed (Chebyshev AO) gives every frame alike: one frame.
        seeded = "seed" in properties.method_group(scene, r["method"]).setting_names
        r["frames"] = frames if seeded else 1
        r["frame"] = 0
        r["histories"] = []   # aolab.TemporalHistory per channel, made by the worker
    return {"exr": str(Path(folder) / library.constants.RESULT_EXR), "runs": runs,
            "radius": inputs["radius"], "threads": inputs["threads"], "size": (w, h),
            "scene": scene.name}


def _start(context) -> None:
    t0 = time.perf_counter()
    plan = snapshot(context)
    if plan is None:
        return
    plan["snapshot_s"] = time.perf_counter() - t0
    _start_worker(plan)


def _is_current(method: str, generation: int) -> bool:
    """Whether a run is still the latest of its method (the worker asks before each run)."""
    return _state.generation.get(method) == generation


def _start_worker(plan: dict) -> None:
    """The worker computes `plan`; its results come back through _apply_results. The
    conversion to Blender's pixels runs there too, so that the main thread only copies."""
    if _state.worker is None:
        _state.worker = library.live_jobs.LiveWorker(_is_current, images.blender_rgba)
    _state.stats["computes"] += 1
    _state.worker.start(plan)


def _apply_results(context) -> None:
    session = context.window_manager.aolab
    while _state.worker is not None and not _state.worker.results.empty():
        item = _state.worker.results.get_nowait()
        method = item["method"]
        stale = item["cancelled"] or item["generation"] != _state.generation.get(method) or \
            item["scene"] != context.scene.name or not session.live
        if stale or item.get("error"):
            _end_accumulation(item)   # another scene or an error: no further frame
        if stale:
            _state.stats["dropped"] += 1
            _state.stats["cancelled"] += item["cancelled"]
            continue
        if item.get("error"):
            _set_message(session, f"{method}: {item['error']}", error=True)
            continue
        t0, cpu0 = time.perf_counter(), time.thread_time()
        name = images.image_name(method)
        images.set_image(name, item["ao"], rgba=item["rgba"])
        done, cpu = time.perf_counter(), time.thread_time() - cpu0
        _store_row(session, context.scene, item, name)
        # total = wait (debounce, snapshot, G-buffer load, earlier runs of the same compute)
        # + compute + rgba (the worker's numpy) + poll (until the timer saw it) + image.
        update = {"method": method, "compute_ms": 1000 * item["compute_s"],
                  "rgba_ms": 1000 * item["rgba_s"],
                  "image_ms": 1000 * (done - t0), "image_cpu_ms": 1000 * cpu,
                  "total_ms": 1000 * (done - item["changed_at"]),
                  "wait_ms": 1000 * (item["started_at"] - item["changed_at"]),
                  "poll_ms": 1000 * (t0 - item["finished_at"]),
                  "snapshot_ms": 1000 * item["snapshot_s"], "load_ms": 1000 * item["load_s"],
                  "accumulate_ms": 1000 * item["accumulate_s"],
                  "generation": item["generation"], "frame": item["frame"],
                  "frames": item["frames"]}
        _state.last = (_state.last + [update])[-64:]
        _state.stats["applied"] += 1
        _converge(item)
        session.live_method, session.live_compute_ms = method, update["compute_ms"]
        session.live_image_ms = update["image_ms"]
        session.live_frame, session.live_frame_goal = item["frame"] + 1, item["frames"]
        if item["frame"] == 0:   # later frames follow no change
            session.live_total_ms = update["total_ms"]
            _set_message(session, f"{method} {update['compute_ms']:.1f} ms compute, "
                         f"{update['total_ms']:.1f} ms from the change to the image",
                         error=False)
        else:
            _set_message(session, f"{method} frame {item['frame'] + 1}/{item['frames']}, "
                         f"{update['compute_ms']:.1f} ms compute", error=False)
        _redraw(context)


def _converge(item: dict) -> None:
    """After a shown frame: the method's next frame is due, or it has converged."""
    if item["frame"] + 1 < item["frames"]:
        run = {k: item[k] for k in ("method", "label", "settings", "blur", "generation",
                                    "frames", "histories")}
        plan = {k: item[k] for k in ("exr", "radius", "threads", "size", "scene")}
        _state.accum[item["method"]] = {"run": run, "plan": plan, "frame": item["frame"] + 1}
    else:
        _end_accumulation(item)


def _end_accumulation(item: dict) -> None:
    """No further frame of the run `item` belongs to (a newer run of the method is kept)."""
    entry = _state.accum.get(item["method"])
    if entry is not None and entry["run"]["histories"] is item.get("histories"):
        del _state.accum[item["method"]]


def _redraw(context) -> None:
    """Redraws the panel's regions and the Image Editors, not the 3D viewport itself (a
    heavy scene's viewport would cost more than the update)."""
    for window in context.window_manager.windows:
        for area in window.screen.areas:
            if area.type == "IMAGE_EDITOR":
                area.tag_redraw()
            elif area.type in ("VIEW_3D", "PROPERTIES"):
                for region in area.regions:
                    if region.type == ("UI" if area.type == "VIEW_3D" else "WINDOW"):
                        region.tag_redraw()


def _set_message(session, text: str, *, error: bool) -> None:
    if session.live_message != text or session.live_message_is_error != error:
        session.live_message, session.live_message_is_error = text, error
        _redraw(bpy.context)


def _store_row(session, scene, item: dict, image: str) -> None:
    """The method's row of the results table: Live's own table (a Preview or Compare table
    of other images or sizes is replaced)."""
    size = f"{item['size'][0]}x{item['size'][1]}"
    if (session.results_kind, session.results_scene, session.results_size) != \
            ("Live", scene.name, size):
        session.results.clear()
        session.results_kind, session.results_scene, session.results_size = \
            "Live", scene.name, size
    row = next((r for r in session.results if r.method == item["method"]), None)
    if row is None:
        row = session.results.add()
    row.method, row.label, row.ms = item["method"], item["label"], 1000 * item["compute_s"]
    row.image, row.error_image, row.has_metrics, row.metrics_json = image, "", False, ""


def _drop_rows(session, methods: list[str]) -> None:
    if session.results_kind != "Live":
        return
    for i in reversed(range(len(session.results))):
        if session.results[i].method in methods:
            session.results.remove(i)


# ---- registration ----

def register() -> None:
    """Live's handlers, and its functions as the hooks the properties' update= callbacks
    call (hooks.py)."""
    _state.__init__()
    bpy.app.handlers.depsgraph_update_post.append(_on_depsgraph)
    bpy.app.handlers.load_pre.append(_on_load)
    hooks.register(live_toggled=on_toggle, setting_changed=on_setting,
                   scene_setting_changed=on_scene_setting)


def unregister() -> None:
    """No hook, timer, handler or computing thread is left behind."""
    hooks.unregister()
    _state.closed = True
    if bpy.app.timers.is_registered(tick):
        bpy.app.timers.unregister(tick)
    for handlers, fn in ((bpy.app.handlers.depsgraph_update_post, _on_depsgraph),
                         (bpy.app.handlers.load_pre, _on_load)):
        if fn in handlers:
            handlers.remove(fn)
    _forget_pending()   # cancels a running compute
    if _state.worker is not None:
        _state.worker.close(JOIN_S)


def pending() -> bool:
    """Whether a change waits or a compute runs (tests)."""
    return bool(_state.dirty) or (_state.worker is not None and _state.worker.pending())
