"""Run by the add-on as `/usr/bin/python3 -m aolab.jobs.reference_job --scene COPY.blend
...` (no bpy; tasks.render_reference).

`aolab reference` for one scene (aolab.reference: the same plan, cache and Blender batch
run as the command line), with its progress printed as lines the add-on parses:

    AOLAB_PROGRESS <done> <total> <stage>     stage: prepare, gbuffer, reference, merge, done
    AOLAB_RESULT {"folder": ..., "cached": ...}
    AOLAB_ERROR <message>                     (exit code 2)

SIGTERM (the add-on's cancel) stops the render: Blender is killed and the temporary folder
removed by aolab.reference; the cache never holds half a result.
"""

import argparse
import json
import signal
import sys
from pathlib import Path

from ..cycles import blender
from ..cycles.plan import make_plan, resolve_scene
from ..cycles.run import render


class LineBar:
    """Stands in for the tqdm bar aolab.cycles.run.render drives (set_description, reset,
    n, total, refresh, close) and prints its state as AOLAB_PROGRESS lines."""

    def __init__(self):
        self.total, self.n, self.stage = 0, 0, "start"

    def set_description(self, desc: str) -> None:
        self.stage = desc.rsplit(": ", 1)[-1]
        self.n = 0
        self.refresh()

    def reset(self, total: int = 0) -> None:
        self.total, self.n = total, 0

    def refresh(self) -> None:
        print(f"AOLAB_PROGRESS {self.n} {self.total} {self.stage}", flush=True)

    def close(self) -> None:
        pass


def main(argv) -> int:
    p = argparse.ArgumentParser(prog="reference_job")
    p.add_argument("--scene", required=True)
    p.add_argument("--spp", type=int, required=True)
    p.add_argument("--radius", type=float, required=True)
    p.add_argument("--resolution", required=True)
    p.add_argument("--passes", default="depth,normal")
    p.add_argument("--cache")
    args = p.parse_args(argv)

    def terminated(signum, frame):
        raise KeyboardInterrupt

    signal.signal(signal.SIGTERM, terminated)
    w, h = (int(v) for v in args.resolution.split("x"))
    try:
        scene = resolve_scene(args.scene)
        plan = make_plan(scene, spp=args.spp, radius=args.radius,
                         passes=args.passes.split(","), resolution=(w, h))
        folder, cached = render(plan, Path(args.cache) if args.cache else None,
                                progress=LineBar())
    except (blender.ReferenceError, ValueError) as e:
        print(f"AOLAB_ERROR {e}", flush=True)
        return 2
    except KeyboardInterrupt:
        print("AOLAB_CANCELLED", flush=True)
        return 130
    print("AOLAB_RESULT " + json.dumps({"folder": str(folder), "cached": cached}), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
