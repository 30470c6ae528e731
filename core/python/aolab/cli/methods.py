"""``aolab methods``: the methods and their settings."""

from __future__ import annotations

import json

import aolab

from ..settings import describe_value


def add_parser(sub):
    m = sub.add_parser("methods", help="list the methods and their settings")
    m.add_argument("--json", action="store_true", help="print the descriptions as JSON")
    return m


def run(args) -> int:
    for name in aolab.methods():
        info = aolab.method_info(name)
        if args.json:
            continue
        print(f"{name}: {info['title']} ({info['paper']})")
        reads = ["depth"] + (["normal"] if info["needs_normal"] else []) + \
            (["color"] if info["needs_color"] else [])
        print(f"  reads: {', '.join(reads)}")
        for s in info["settings"]:
            print(f"  {s['name']:<22} {s['type']:<6} default {s['default']!s:<8} "
                  f"{describe_value(s)}  {s['description']}")
    if args.json:
        print(json.dumps([aolab.method_info(n) for n in aolab.methods()], indent=2))
    return 0
