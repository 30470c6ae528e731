#!/usr/bin/python3
"""Screenshots of the comparison report for docs/comparison.md, taken in headless Chromium
(tests/python/support/browser.py, the report tests' driver): a point's hover in the "All scenes" MAE
plot (docs/images/report_hover.png) and the image viewer a click on it opens
(docs/images/report_viewer.png). Run on a complete study's report, after scripts/build.sh:

    PYTHONPATH=build/python /usr/bin/python3 scripts/report_screenshot.py out/compare/report.html \
        [--method hbao | --key ALL/hbao/medium] [--out docs/images]

The point is --key's, or the method's point farthest from every other (so that the hover
and the click show it alone).
"""
import argparse
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "python"))

from browser import Browser, plot_point, poll  # noqa: E402 (the tests' folder, above)

PLOT = "plot-ALL-all_mae"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("report", type=Path)
    parser.add_argument("--method", default="hbao",
                        help="hover and click this method's most isolated point")
    parser.add_argument("--key", help="hover and click this row's point instead")
    parser.add_argument("--out", type=Path, default=ROOT / "docs" / "images")
    args = parser.parse_args()
    with Browser(width=1400, height=900) as b:
        b.open(args.report)
        if not poll(b, "document.title.startsWith('AO Lab report: ok')"):
            print(f"report_screenshot: {b.evaluate('document.title')}", file=sys.stderr)
            return 1
        at = plot_point(b, PLOT, name=None if args.key else args.method, key=args.key)
        if at is None:
            print(f"report_screenshot: no point {args.key or args.method} in {PLOT}",
                  file=sys.stderr)
            return 2
        b.mouse("mouseMoved", at["x"], at["y"])
        if not poll(b, f"!!document.querySelector('#{PLOT} .hovertext')"):
            print("report_screenshot: no hover appeared", file=sys.stderr)
            return 1
        box = b.evaluate(f"(() => {{ const r = document.getElementById('{PLOT}')"
                         ".getBoundingClientRect(); return {x: r.left + window.scrollX, "
                         "y: r.top + window.scrollY, width: r.width, height: r.height}; })()")
        b.screenshot(args.out / "report_hover.png", clip=box)
        b.mouse("mousePressed", at["x"], at["y"])
        b.mouse("mouseReleased", at["x"], at["y"])
        poll(b, "(() => { const v = document.getElementById('viewer'); const i = "
                "Array.from(v.querySelectorAll('img')); return !v.hidden && i.length && "
                "i.every(x => x.complete && x.naturalWidth); })()")
        time.sleep(0.2)
        b.screenshot(args.out / "report_viewer.png")
        if b.errors:
            print("report_screenshot: the page reported errors:", *b.errors, sep="\n  ",
                  file=sys.stderr)
            return 1
    print(f"report_screenshot: {args.out / 'report_hover.png'}, {args.out / 'report_viewer.png'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
