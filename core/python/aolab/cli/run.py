"""``aolab run``: one method's AO of a G-buffer, written as EXR and PNG and scored."""

from __future__ import annotations

import argparse
import time

import aolab

from ..util.arguments import float_option, int_option
from .common import (check_outputs, gbuffer_files, input_options, key_values, load_input,
                     output_stem, write_result)


def add_parser(sub):
    r = sub.add_parser("run", help="compute AO for a G-buffer and score it")
    r.add_argument("method", choices=aolab.methods())
    r.add_argument("input", help="G-buffer .exr (with sidecar) or analytic:NAME")
    input_options(r)
    r.add_argument("--out", help="output path without extension: writes OUT.exr and OUT.png "
                   "(a trailing .exr or .png is dropped; another extension, such as .txt, is "
                   "refused); an existing folder or a path ending in / gets METHOD_ao.exr and "
                   ".png inside it (default METHOD_ao in the current folder); an OUT.exr or "
                   "OUT.png that is the input or its sidecar is refused")
    r.add_argument("--preset", help="a named preset of the method (`aolab presets METHOD`: "
                   "default, low, medium, high, ultra, tuned-...); --set and --blur/--no-blur "
                   "override it")
    r.add_argument("--blur", action=argparse.BooleanOptionalAction, default=None,
                   help="apply the separable Gaussian blur (default: the preset's, else off)")
    sigma = float_option("--blur-sigma", 0.1, 64, lo_inclusive=True, unit="px")
    r.add_argument("--blur-sigma", type=sigma, default=1.5,
                   help="the blur's standard deviation, 0.1 to 64 px (default 1.5)")
    r.add_argument("--blur-taps", type=int_option("--blur-taps", 1, 129, odd=True), default=5,
                   help="the blur's taps per pass, odd, 1 to 129 (default 5)")
    r.add_argument("--json", help="also write the result (timing, metrics) to this JSON file "
                   "(never the input, its sidecar or an --out file: refused before any work)")
    return r


def run(args) -> int:
    settings = key_values(args.set, args.method)
    out = output_stem(args.out, args.method)
    check_outputs(out, args.json, gbuffer_files(args.input))
    g, radius = load_input(args.input, args.radius, args.width, args.height)
    kwargs = dict(radius=radius, threads=args.threads, preset=args.preset, blur=args.blur,
                  blur_sigma=args.blur_sigma, blur_taps=args.blur_taps, **settings)
    t0 = time.perf_counter()
    ao = aolab.compute(args.method, g, **kwargs)
    elapsed = time.perf_counter() - t0
    result = {"method": args.method, "input": args.input, "width": g.width, "height": g.height,
              "radius": radius, "preset": args.preset, "settings": settings,
              "threads": args.threads, "seconds": elapsed}
    write_result(g, ao, out, result, args.json,
                 f"{args.method}: {g.width}x{g.height}, radius {radius:g}, "
                 f"{elapsed * 1000:.1f} ms")
    return 0
