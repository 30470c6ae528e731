"""``aolab presets``: the named presets of each method and their settings."""

from __future__ import annotations

import json

import aolab


def add_parser(sub):
    q = sub.add_parser("presets", help="the named presets of each method and their settings")
    q.add_argument("methods", nargs="*", metavar="METHOD", help="methods (default: all)")
    q.add_argument("--json", action="store_true", help="print them as JSON")
    return q


def run(args) -> int:
    every = {m: aolab.presets(m) for m in args.methods or aolab.methods()}
    if args.json:
        print(json.dumps(every, indent=2))
        return 0

    def shown(v):   # floats at the single precision the methods keep
        return f"{v:.7g}" if isinstance(v, float) else str(v)
    for method, named in every.items():
        print(f"{method}:")
        for name, values in named.items():
            print(f"  {name:<14} " + ", ".join(f"{k}={shown(v)}" for k, v in values.items()))
    return 0
