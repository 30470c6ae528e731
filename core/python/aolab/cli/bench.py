"""``aolab bench``: the median time of one method over repeated runs."""

from __future__ import annotations

import os
import platform
import statistics

import aolab
from aolab.study.runner import timed

from .common import input_options, key_values, load_input
from .options import add_timing_options


def add_parser(sub):
    b = sub.add_parser("bench", help="median time of a method over repeated runs")
    b.add_argument("method", choices=aolab.methods())
    b.add_argument("input", nargs="?", default="analytic:blocks")
    input_options(b, threads=False)
    add_timing_options(b, repeat=7, warmup=1, repeat_help="timed runs (their median)")
    return b


def run(args) -> int:
    settings = key_values(args.set, args.method)
    g, radius = load_input(args.input, args.radius, args.width, args.height)
    # timed as aolab compare times: one timing function for every command
    _, times = timed(lambda: aolab.compute(args.method, g, radius=radius, threads=args.threads,
                                           **settings), args.warmup, args.repeat)
    med = statistics.median(times)
    spread = (max(times) - min(times)) if len(times) > 1 else 0.0
    cpu = platform.processor() or platform.machine()
    print(f"{args.method} on {args.input} {g.width}x{g.height}, radius {radius:g}, "
          f"threads {args.threads or os.cpu_count()}, {cpu}: "
          f"median {med:.1f} ms over {args.repeat} runs (spread {spread:.1f} ms)")
    return 0
