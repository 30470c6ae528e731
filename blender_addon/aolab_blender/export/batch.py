"""Entry point run inside Blender by `aolab reference` (blender -b ... --python batch.py -- ...).

    --scene PATH        a .blend (already opened by Blender, with --disable-autoexec) or a
                        build script (.py) run into an empty factory file
    --kind blend|script
    --out FILE.exr      where the merged G-buffer + reference goes (sidecar beside it); a
                        file it writes that is the scene (--scene, the open .blend) or
                        another of its files is refused before anything runs
    --radius R          AO distance (default: the scene world's AO distance)
    --spp N             reference samples          --gbuffer-samples N (default 1)
    --passes a,b        G-buffer passes (depth always)
    --resolution WxH    override the scene's resolution (percentage 100)
    --scale PCT         render at PCT % of the output size (after --resolution), as the
                        add-on's Resolution does (its minimum 4x4 checked)
    --camera NAME       render from this camera instead of the scene camera
    --extra JSON        extra sidecar entries
    --peers             render the comparison peers instead (Cycles ladder, EEVEE;
                        peers.py): --out is then a folder
    --ladder 1,4,...    the ladder's samples (none: no rung)     --no-eevee   skip EEVEE
    --frame N           render animation frame N (scene.frame_set; recorded as "frame")
    --mesh-only         export only the scene's geometry, no render (mesh.py): --out
                        is then the .mesh (its .mesh.json beside it); --radius, --spp and
                        --passes do not apply

Prints `AOLAB_STAGE <stage>` lines, `AOLAB_ERROR <message>` on a problem the user can act
on (exit code 2), and `AOLAB_RESULT <sidecar json>` on success.

Run as a file, not imported: it puts the folder that holds the add-on's package
(blender_addon/) first on sys.path, and before it the folder of the aolab package that started
Blender ($AOLAB_PACKAGE_PATH, set by aolab.cycles.blender), so that Blender uses that same build.
"""

import json
import os
import runpy
import sys
import traceback

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
if os.environ.get("AOLAB_PACKAGE_PATH"):
    sys.path.insert(0, os.environ["AOLAB_PACKAGE_PATH"])

import bpy  # noqa: E402
from aolab.bridge.constants import LADDER_SPP  # noqa: E402
from aolab.bridge.passes import parse_passes  # noqa: E402
from aolab.util.arguments import (MAX_SAMPLES, Parser, checked_type, float_option,  # noqa: E402
                                  int_list_option, int_option)
from aolab.bridge.intrinsics import image_size  # noqa: E402
from aolab.bridge.outputs import check_export  # noqa: E402
from aolab.util.arguments import MAX_FRAME, MIN_RESOLUTION, parse_resolution  # noqa: E402

from aolab_blender.export import mesh, peers, reference  # noqa: E402
from aolab_blender.export.scene_record import BridgeError  # noqa: E402


def _extra(text: str) -> dict:
    try:
        value = json.loads(text)
    except ValueError as e:
        raise ValueError(f"--extra must be a JSON object, got {text[:60]!r} ({e})") from None
    if not isinstance(value, dict):
        raise ValueError(f"--extra must be a JSON object, got {type(value).__name__}")
    return value


def parse(argv):
    """The options, each checked with its range when read (argparse's usage line and
    `argument --OPT: ...`, exit status 2), as `aolab reference` checks its own."""
    p = Parser(prog="aolab_blender.export.batch")
    p.add_argument("--scene", required=True)
    p.add_argument("--kind", choices=("blend", "script"), required=True)
    p.add_argument("--out", required=True)
    p.add_argument("--radius", type=float_option("--radius", unit="scene units", float32=True))
    p.add_argument("--spp", type=int_option("--spp", 1, MAX_SAMPLES), default=1024)
    p.add_argument("--gbuffer-samples", type=int_option("--gbuffer-samples", 1, MAX_SAMPLES),
                   default=1)
    p.add_argument("--passes", type=checked_type(parse_passes, "--passes"), default="depth,normal")
    p.add_argument("--resolution", type=checked_type(parse_resolution, "--resolution"))
    p.add_argument("--camera")
    p.add_argument("--extra", type=checked_type(_extra, "--extra"), default="{}")
    p.add_argument("--peers", action="store_true")
    p.add_argument("--ladder", type=int_list_option("--ladder", MAX_SAMPLES),
                   default=",".join(str(s) for s in LADDER_SPP))
    p.add_argument("--no-eevee", action="store_true")
    p.add_argument("--mesh-only", action="store_true")
    p.add_argument("--frame", type=int_option("--frame", -MAX_FRAME, MAX_FRAME))
    p.add_argument("--scale", type=int_option("--scale", 1, 100))
    return p.parse_args(argv)


def scale_output(render, percent: int) -> None:
    """The output size made `percent` % of what it is (resolution x percentage, each side
    truncated as Blender and the add-on's Resolution truncate, percentage 100); a BridgeError
    when a side would fall below Blender's 4-pixel minimum, which it would raise silently."""
    w, h = image_size(render.resolution_x, render.resolution_y, render.resolution_percentage)
    size = max(1, w * percent // 100), max(1, h * percent // 100)
    if min(size) < MIN_RESOLUTION:
        raise BridgeError(f"at {percent} % of {w}x{h} the render would be {size[0]}x{size[1]}; "
                          f"Blender renders at least {MIN_RESOLUTION}x{MIN_RESOLUTION}: "
                          "raise the scale")
    render.resolution_x, render.resolution_y = size
    render.resolution_percentage = 100


def main(argv):
    args = parse(argv)
    # Before the scene runs or renders: no file the export writes is the scene itself.
    scene_files = {"--scene": args.scene, "the open .blend": bpy.data.filepath or None}
    check_export(args.out, scene_files, passes=args.passes, mesh_only=args.mesh_only,
                 peers=args.peers)
    if args.kind == "script":
        bpy.ops.wm.read_factory_settings(use_empty=True)
        runpy.run_path(args.scene, run_name="__main__")
    scene = bpy.context.scene
    if args.frame is not None:
        # Animation (camera paths, moving objects) is evaluated at this frame for the G-buffer,
        # the reference and the mesh alike.
        scene.frame_set(args.frame)
        args.extra = {**args.extra, "frame": args.frame}
    if args.resolution:
        scene.render.resolution_x, scene.render.resolution_y = args.resolution
        scene.render.resolution_percentage = 100
    if args.scale is not None:
        scale_output(scene.render, args.scale)

    def stage(name: str) -> None:
        print(f"AOLAB_STAGE {name}", flush=True)

    if args.mesh_only:
        info = mesh.export_mesh(scene, args.out, camera_name=args.camera, report=stage,
                                extra=args.extra)
        print("AOLAB_RESULT " + json.dumps(info), flush=True)
        return
    radius = args.radius
    if radius is None:
        if scene.world is None:
            raise BridgeError("the scene has no world, so no AO distance: pass --radius")
        radius = scene.world.light_settings.distance

    if args.peers:
        result = peers.render_peers(
            scene, args.out, radius=radius, ladder=args.ladder,
            eevee=not args.no_eevee, camera_name=args.camera, report=stage, extra=args.extra)
        print("AOLAB_RESULT " + json.dumps(result), flush=True)
        return
    sidecar = reference.export_reference(
        scene, args.out, radius=radius, spp=args.spp, passes=args.passes,
        gbuffer_samples=args.gbuffer_samples, camera_name=args.camera,
        report=stage, extra=args.extra)
    print("AOLAB_RESULT " + json.dumps(sidecar), flush=True)


if __name__ == "__main__":
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    try:
        main(argv)
    except (BridgeError, ValueError, OSError) as e:
        # OSError: an --out under a regular file, a full disk, a folder without write access
        print(f"AOLAB_ERROR {e if str(e) else type(e).__name__}", flush=True)
        sys.exit(2)
    except Exception:
        # The last lines of the traceback in the message: `aolab reference` shows the message
        # alone, and the whole traceback is above it in Blender's output.
        last = traceback.format_exc().strip().splitlines()[-3:]
        traceback.print_exc()
        print("AOLAB_ERROR unexpected failure inside Blender: " + " | ".join(
            line.strip() for line in last), flush=True)
        sys.exit(3)
