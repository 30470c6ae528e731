"""Shared pieces of the comparison-study tests: a small scenes folder built from committed
references (one with synthetic peers, one without) and a helper to run ``aolab compare``."""
from __future__ import annotations

import csv
import json
import shutil
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import OpenImageIO as oiio

import aolab
from aolab import cli

ROOT = Path(__file__).resolve().parents[3]
SCENES = ROOT / "reference_scenes"
LADDER = (1, 4, 16, 64, 256)
CROP = "160x90"


def write_y_exr(path: Path, image: np.ndarray, half: bool = True) -> None:
    """A one-channel EXR named Y, as `aolab reference --peers` writes the peers."""
    h, w = image.shape
    spec = oiio.ImageSpec(w, h, 1, oiio.HALF if half else oiio.FLOAT)
    spec.channelnames = ("Y",)
    out = oiio.ImageOutput.create(str(path))
    assert out is not None and out.open(str(path), spec), oiio.geterror()
    out.write_image(np.ascontiguousarray(image[..., None], np.float32))
    out.close()


def copy_files(src: Path, dst: Path, names) -> None:
    """Copies of ``src``'s files ``names`` in ``dst`` (made if missing): a scene's files are
    regular files inside its folder (a symbolic link among them is refused)."""
    dst.mkdir(parents=True, exist_ok=True)
    for name in names:
        shutil.copyfile(src / name, dst / name)


def link_scene(src: Path, dst: Path, mesh: bool = False) -> None:
    """A scene folder ``dst`` with copies of ``src``'s reference, sidecar and manifest (and
    mesh)."""
    dst.mkdir(parents=True)
    names = ["reference.exr", "reference.json", "manifest.json"]
    if mesh:   # the scene's triangles: the study then runs rtao on it
        names += ["reference.mesh", "reference.mesh.json"]
    copy_files(src, dst, names)


def write_synthetic_peers(folder: Path, seed: int = 7) -> dict:
    """peers/peers.json and its EXRs for a scene folder: the reference plus binomial-like noise
    of variance v(1 - v)/N for N spp (Cycles ladder and an independent 1024-spp render) and a
    blurred, brightened reference standing in for EEVEE. Background stays 1."""
    g = aolab.load_gbuffer(folder / "reference.exr")
    ref = np.asarray(g.reference, np.float64)
    valid = g.valid_mask()
    rng = np.random.default_rng(seed)
    peers = folder / "peers"
    peers.mkdir()
    entries = []

    def noisy(n):
        sd = np.sqrt(np.clip(ref * (1 - ref), 0, None) / n)
        return np.where(valid, np.clip(ref + rng.normal(size=ref.shape) * sd, 0, 1), 1.0)

    for i, n in enumerate(LADDER):
        name = f"cycles_{n}spp"
        write_y_exr(peers / f"{name}.exr", noisy(n), half=(i % 2 == 0))
        entries.append({"name": name, "kind": "cycles", "samples": n, "file": f"{name}.exr",
                        "render_time_s": 0.05 * n + 0.4, "seed": 1})
    write_y_exr(peers / "cycles_1024spp_seed2.exr", noisy(1024), half=False)
    entries.append({"name": "cycles_1024spp_seed2", "kind": "noise_floor", "samples": 1024,
                    "file": "cycles_1024spp_seed2.exr", "render_time_s": 52.0, "seed": 2})
    eevee = np.where(valid, np.clip(0.3 + 0.75 * ref, 0, 1), 1.0)
    write_y_exr(peers / "eevee_gtao.exr", eevee)
    entries.append({"name": "eevee_gtao", "kind": "eevee", "file": "eevee_gtao.exr",
                    "render_time_s": 3.5, "settings": {"gtao_distance": 0.5},
                    "note": "EEVEE on Mesa llvmpipe (software rasteriser): time not comparable"})
    manifest = {"entries": entries}
    (peers / "peers.json").write_text(json.dumps(manifest, indent=1))
    return manifest


#: The synthetic limits of write_synthetic_limits: name -> (label, darkening of the reference).
SYNTHETIC_LIMITS = {"screen_space_limit_t0.25R": ("T = 0.25 R", 0.02),
                    "screen_space_limit_t_inf": ("T = ∞ (height field)", 0.15)}


def write_synthetic_limits(folder: Path) -> dict:
    """limits/limits.json and its EXRs, as `aolab limits` writes them: the reference darkened
    by a constant per thickness (the height field over-occludes most), so that the study's
    choice of the best thickness is known."""
    g = aolab.load_gbuffer(folder / "reference.exr")
    ref = np.asarray(g.reference, np.float64)
    valid = g.valid_mask()
    out = folder / "limits"
    out.mkdir()
    entries = []
    for name, (label, dark) in SYNTHETIC_LIMITS.items():
        write_y_exr(out / f"{name}.exr", np.where(valid, np.clip(ref - dark, 0, 1), 1.0))
        entries.append({"name": name, "kind": "limit", "label": label, "file": f"{name}.exr",
                        "render_time_s": 90.0, "rays": 256})
    manifest = {"entries": entries}
    (out / "limits.json").write_text(json.dumps(manifest, indent=1))
    return manifest


def make_scenes(tmp: Path) -> Path:
    """tmp/scenes with room (synthetic peers and limits, and its mesh: rtao runs) and grille
    (none of them)."""
    scenes = tmp / "scenes"
    link_scene(SCENES / "room", scenes / "room", mesh=True)
    link_scene(SCENES / "grille", scenes / "grille")
    write_synthetic_peers(scenes / "room")
    write_synthetic_limits(scenes / "room")
    return scenes


def read_csv(path: Path) -> list[dict]:
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


class PlotPoints(HTMLParser):
    """Collects every plotted point and horizontal line of report.html, with the attributes of
    a static (SVG) point: data-key, data-metric, data-x, data-y; from the SVG elements and from
    the plotly.js figures (charts.plotly_figure: a series trace's customdata are the keys,
    layout.meta.column the metric; an hline trace's meta names its row). ``figures``: plot id
    -> its plotly.js figure; ``images_index``: the page's image files of every scene."""

    def __init__(self):
        super().__init__()
        self.points, self.hlines, self.plots, self.images = [], [], [], []
        self.bars, self.checks = [], []
        self.figures: dict[str, dict] = {}
        self.images_index: dict = {}
        self._figure: str | None = None
        self._text: list[str] = []

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        classes = (a.get("class") or "").split()
        if "point" in classes:
            self.points.append(a)
        if "hline" in classes and "data-key" in a:
            self.hlines.append(a)
        if tag in ("svg", "div") and "plot" in classes:
            self.plots.append(a)
        if tag == "img":
            self.images.append(a)
        if "bar" in classes:
            self.bars.append(a)
        if tag == "tr" and "data-verdict" in a:
            self.checks.append(a)
        if tag == "script" and ("figure" in classes or "images" in classes):
            self._figure, self._text = a.get("data-plot", ""), []

    def handle_data(self, data):
        if self._figure is not None:
            self._text.append(data)

    def handle_endtag(self, tag):
        if tag != "script" or self._figure is None:
            return
        fig = json.loads("".join(self._text))
        if not self._figure:     # the images of every scene (report.Page.index)
            self.images_index, self._figure = fig, None
            return
        self.figures[self._figure] = fig
        column = fig["layout"]["meta"]["column"]
        for t in fig["data"]:
            meta = t.get("meta") or {}
            if meta.get("role") == "series":
                self.points += [{"data-key": k, "data-metric": column, "data-x": x,
                                 "data-y": y, "class": "point"}
                                for k, x, y in zip(t["customdata"], t["x"], t["y"])]
            elif meta.get("role") == "hline":
                self.hlines.append({"data-key": meta["key"], "data-metric": column,
                                    "data-y": t["y"][0], "class": "hline " + meta["cls"]})
        self._figure = None


def parse_report(path: Path) -> PlotPoints:
    p = PlotPoints()
    p.feed(Path(path).read_text(encoding="utf-8"))
    return p


#: The synthetic sequence of make_sequence: frames 1, 3, 5, 7 (step 2) of a 96x54 window
#: into room that moves SHIFT px to the right from one frame to the next.
SEQUENCE_FRAMES = {"start": 1, "end": 7, "step": 2}
SEQUENCE_SIZE = (96, 54)
SEQUENCE_SHIFT = 4


def make_sequence(scenes: Path, name: str = "pan", *, motion: bool = False,
                  frames: dict = SEQUENCE_FRAMES, shift: int = SEQUENCE_SHIFT) -> Path:
    """A sequence scene folder cut from room's committed reference: each frame the same-sized
    window moved ``shift`` px right of the frame before, its sidecar's cx moved with it,
    so the camera pans (a shift of the principal point is a pan of a pinhole camera's image
    plane; the reference, rendered once, is exact for every frame). With ``motion`` every
    frame carries its exact motion vectors (add_motion): the content moves ``shift`` px left,
    so dx = +shift, dy = 0."""
    g = aolab.load_gbuffer(SCENES / "room" / "reference.exr")
    folder = scenes / name
    folder.mkdir(parents=True)
    manifest = json.loads((SCENES / "room" / "manifest.json").read_text())
    manifest.update(name=name, title="room, panned", frames=frames,
                    resolution=list(SEQUENCE_SIZE))
    (folder / "manifest.json").write_text(json.dumps(manifest, indent=1))
    w, h = SEQUENCE_SIZE
    f = frames
    for i, frame in enumerate(range(f["start"], f["end"] + 1, f["step"])):
        x0, y0 = 560 + shift * i, 380
        window = (slice(y0, y0 + h), slice(x0, x0 + w))
        crop = aolab.GBuffer(np.ascontiguousarray(g.depth[window]),
                             np.ascontiguousarray(g.normal[window]),
                             fx=g.fx, fy=g.fy, cx=g.cx - x0, cy=g.cy - y0,
                             background_depth=g.background_depth)
        out = folder / "frames" / f"{frame:04d}"
        out.mkdir(parents=True)
        aolab.save_gbuffer(out / "reference.exr", crop,
                           reference=np.ascontiguousarray(g.reference[window]),
                           sidecar={"ao_distance": g.sidecar["ao_distance"],
                                    "samples": g.sidecar["samples"], "frame": frame})
        if motion:
            pan = np.full((h, w, 2), [float(shift), 0.0], np.float32)
            add_motion(out / "reference.exr", pan)
    return folder


def add_motion(path: Path, motion: np.ndarray) -> None:
    """Rewrites the G-buffer EXR ``path`` with a Motion pass ``motion`` (H, W, 2) in pixels
    (NaN on background is set by the reader), every other pass as it was, in float."""
    from aolab.bridge import exr
    from aolab.bridge.motion import layer_prefix
    channels = exr.read_channels(str(path))
    prefix = layer_prefix(list(channels))
    layers = []
    for pass_name, comps in exr.LAYER_COMPONENTS.items():
        names = [f"{prefix}{pass_name}.{c}" for c in comps]
        if pass_name != "Motion" and all(n in channels for n in names):
            layers.append((pass_name, np.stack([channels[n] for n in names], -1), "float"))
    layers.append(("Motion", np.asarray(motion, np.float32), "float"))
    exr.write_multilayer(str(path), layers, view_layer=prefix.rstrip(".") or "ViewLayer")


def run_compare(scenes: Path, out: Path, *extra) -> int:
    return cli.main(["compare", "--scenes-dir", str(scenes), "--out", str(out), "--crop", CROP,
                     "--repeat", "2", "--warmup", "0", "--threads", "2", "--no-progress",
                     *extra])
