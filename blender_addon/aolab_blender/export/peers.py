"""The comparison study's peers of a scene (bpy): what the reference costs, and Blender's own
screen-space AO.

render_peers() renders, from the same camera, at the same AO distance and resolution:
- the Cycles ladder: the AO pass at 1, 4, 16, 64, 256 spp with the reference's settings
  (reference.render_session) but seed 1, so that no rung shares samples with the seed-0
  1024-spp reference — each is an independent estimate, scored against it like a method;
- the noise floor: the study derives it from the 256-spp rung (256 against 1024 spp;
  docs/comparison.md), so no second 1024-spp render is needed;
- EEVEE: the AO pass of Blender's rasteriser at distance R, with the settings of this
  Blender's EEVEE (compat.eevee_ao_settings): GTAO on 3.4 ("eevee_gtao": factor 1, bounce
  approximation off, as it brightens AO, which the Cycles pass does not), EEVEE Next's horizon
  scan on 4.2+ ("eevee_next"). EEVEE needs an OpenGL context: under `xvfb-run` Mesa's
  llvmpipe renders it on the CPU, so its time is not comparable with ours or with Cycles'.

Each image is a one-channel half EXR ("Y") with background pixels set to 1 (our convention),
listed with its render time in peers.json (docs/comparison.md). Every setting is restored.
"""

from __future__ import annotations

import json
import math
import os
import platform

import bpy

from aolab.util import files
from aolab.bridge import exr
from aolab.bridge.constants import BACKGROUND_DEPTH, LADDER_SEED, LADDER_SPP, PEERS_JSON

from . import compat
from .reference import enable_only_passes, render_session, render_to
from .scene_record import BridgeError, Cancelled, camera_record, content_hash, scene_camera
from .state import SettingsRestorer


def _ao_and_background(path: str, background_depth: float):
    """The AO pass of a render (R of AO.RGB) with 1 where its depth says background."""
    channels = exr.read_channels(path)
    ao = exr.find_pass(channels, "AO", ("R", "G", "B"))
    depth = exr.find_pass(channels, "Depth", ("Z",))
    if ao is None or depth is None:
        raise BridgeError(f"the render lacks AO or Depth; channels: {sorted(channels)}")
    ao = ao[..., 0].copy()
    ao[~(depth[..., 0] < background_depth)] = 1.0
    return ao


def _eevee_settings(rs: SettingsRestorer, scene, radius: float) -> dict:
    rs.set(scene.render, "engine", compat.eevee_engine())
    chosen = compat.eevee_ao_settings(scene.eevee, radius)
    for attr, value in chosen.items():
        rs.set(scene.eevee, attr, value)
    rs.set(scene.render, "filter_size", 0.01)  # pixel-centre values, like the Cycles renders
    chosen["filter_size"] = 0.01
    return chosen


def render_peers(scene, out_dir: str, *, radius: float, ladder=LADDER_SPP, eevee: bool = True,
                 camera_name: str | None = None, cancel=None, report=print,
                 extra: dict | None = None) -> dict:
    """Renders the peers of `scene` into `out_dir` (EXRs + peers.json) and returns the
    peers.json content. `cancel()` is polled between renders (Cancelled); `report(stage)`
    announces each. Settings are restored in every case."""
    if not (math.isfinite(radius) and radius > 0):
        raise BridgeError(f"radius must be a finite number > 0 (the AO distance in scene "
                          f"units), got {radius}")
    if any(int(s) < 1 for s in ladder) or not (ladder or eevee):
        raise BridgeError(f"ladder samples must be >= 1 (none: EEVEE alone), got {list(ladder)}")
    cam = scene_camera(scene, camera_name)
    view_layer = bpy.context.view_layer
    os.makedirs(out_dir, exist_ok=True)

    def checkpoint(stage: str):
        if cancel is not None and cancel():
            raise Cancelled()
        report(stage)

    entries = []
    load_before = list(os.getloadavg())
    with render_session(scene, cam, radius, out_dir, "aolab-peers-", checkpoint) as (tmp, rs):
        record = camera_record(scene, cam)
        scene_hash = content_hash(scene, cam)
        rs.set(scene.cycles, "seed", LADDER_SEED)
        enable_only_passes(rs, view_layer, {"use_pass_ambient_occlusion", "use_pass_z"})
        for obj in scene.objects:  # AO alone, as the reference
            if obj.type == "LIGHT":
                rs.set(obj, "hide_render", True)
        for spp in ladder:
            checkpoint(f"cycles {spp} spp")
            rs.set(scene.cycles, "samples", int(spp))
            path = os.path.join(tmp, f"cycles_{spp}spp.exr")
            seconds = render_to(rs, scene, path)
            name = f"cycles_{spp}spp"
            exr.write_gray(os.path.join(out_dir, name + ".exr"),
                           _ao_and_background(path, BACKGROUND_DEPTH))
            entries.append({"name": name, "kind": "cycles", "samples": int(spp),
                            "file": name + ".exr", "render_time_s": seconds,
                            "seed": LADDER_SEED})
        if eevee:
            checkpoint("eevee")
            chosen = _eevee_settings(rs, scene, radius)
            path = os.path.join(tmp, "eevee.exr")
            seconds = render_to(rs, scene, path)
            name = compat.eevee_peer_name()
            exr.write_gray(os.path.join(out_dir, name + ".exr"),
                           _ao_and_background(path, compat.eevee_background_depth(cam.data)))
            entries.append({"name": name, "kind": "eevee", "file": name + ".exr",
                            "render_time_s": seconds, "settings": chosen,
                            "note": "EEVEE on Mesa llvmpipe (software rasteriser under Xvfb): "
                                    "time not comparable"})
        peers = {"entries": entries, "ao_distance": radius, "camera": record,
                 "scene_hash": scene_hash, "blender_version": bpy.app.version_string,
                 "machine": {"cpu": platform.processor() or platform.machine(),
                             "cores": os.cpu_count(),
                             "load_average_before": load_before,
                             "load_average_after": list(os.getloadavg())},
                 **(extra or {})}
        files.write_text(os.path.join(out_dir, PEERS_JSON), json.dumps(peers, indent=1))
        report("done")
        return peers
