"""``aolab analytic``: an analytic scene's G-buffer EXR and sidecar."""

from __future__ import annotations

import os
from pathlib import Path

import aolab

from ..util import files
from ..util.arguments import MAX_SIDE
from .common import RADIUS, SIDE, existing_ancestor_is_not_a_folder, key_values


def add_parser(sub):
    a = sub.add_parser("analytic", help="write an analytic scene's G-buffer EXR and sidecar")
    a.add_argument("name", choices=aolab.analytic_scene_names())
    a.add_argument("output", help="output .exr path (the sidecar goes beside it: "
                   "OUTPUT without its extension + .json, so OUTPUT must not end in .json)")
    a.add_argument("--width", type=SIDE["--width"], default=1280,
                   help=f"1 to {MAX_SIDE} (default 1280)")
    a.add_argument("--height", type=SIDE["--height"], default=720,
                   help=f"1 to {MAX_SIDE} (default 720)")
    a.add_argument("--radius", type=RADIUS, help="R of the closed-form reference, finite > 0 "
                   "(default 1)")
    a.add_argument("--param", action="append", metavar="KEY=VALUE",
                   help="scene parameter, e.g. --param tilt=60 (repeatable)")
    return a


def run(args) -> int:
    params = key_values(args.param)
    if args.radius is not None:
        params["radius"] = args.radius
    out = Path(args.output)
    blocker = existing_ancestor_is_not_a_folder(out)
    if blocker is not None:
        raise ValueError(f"output {args.output!r}: {blocker} is a file, not a folder")
    if out.is_dir() or args.output.endswith(("/", os.sep)):
        raise ValueError(f"output must be an .exr file path, got {args.output!r}, a folder")
    files.check_distinct(writes={"OUTPUT": out, "OUTPUT's sidecar": out.with_suffix(".json")})
    g = aolab.analytic_scene(args.name, args.width, args.height, **params)
    out.parent.mkdir(parents=True, exist_ok=True)
    aolab.save_gbuffer(out, g, reference=g.reference, sidecar=g.sidecar)
    print(f"wrote {out} and {out.with_suffix('.json')} ({args.width}x{args.height}, "
          f"radius {params.get('radius', 1.0)})")
    return 0
