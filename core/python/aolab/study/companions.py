"""The rows beside the methods' rows in ``aolab compare``: the peers of a scene (the Cycles
ladder, an independent reference, EEVEE, the screen-space limits), rtao at each rung of its
ladder against the scene's mesh, and the reference's own noise floor; and which peers the
report's image grid shows. compare.Study runs the methods and calls these for the rest."""

import math
import warnings

import aolab

from ..regions import REGIONS
from ..scenes import Scene, noise_floor_peer
from .results import LIMIT_KIND, make_row, score_row
from .runner import Timing, time_fields, timed, vs_limit

#: Peers whose images the report shows: those plotted (the Cycles ladder, EEVEE) and the
#: screen-space limits (the image grid shows the chosen one).
IMAGED_PEERS = ("cycles", "eevee", LIMIT_KIND)


# ----------------------------------------------------------------------------------------
# Peers


def peer_rows(scene: Scene, info: dict) -> list[dict]:
    """The scored row of every peer of ``scene``. Sets the scene's screen-space limit (the
    limit peer with the lowest occluded MAE: ``scene.limit`` and ``info["limit"]``, ``info``
    being the scene's entry of results.json's scenes), then every other peer's MAE against
    it."""
    mine = []
    for p in scene.peers:
        ms = p.render_time_s * 1000 if p.render_time_s is not None else None
        settings = {k: v for k, v in p.entry.items()
                    if k not in ("name", "kind", "file", "render_time_s", "note")}
        row = make_row(scene, p.kind, p.name, p.entry.get("label", p.name), preset="",
                       settings=settings, method_ms=ms, total_ms=ms, runs=1 if ms else None,
                       note=p.entry.get("note", ""))
        score_row(scene, row, p.ao)
        mine.append((p, row))
    limits = [(p, r) for p, r in mine if p.kind == LIMIT_KIND
              and math.isfinite(r["metrics"]["occluded"]["mae"])]
    if limits:
        p, r = min(limits, key=lambda pr: pr[1]["metrics"]["occluded"]["mae"])
        scene.limit = p
        info["limit"] = {
            "key": r["key"], "name": p.name, "label": r["label"],
            "thickness_r": p.entry.get("thickness_r"),
            **{f"{reg}_mae": r["metrics"][reg]["mae"] for reg in REGIONS}}
    for p, r in mine:
        if p.kind != LIMIT_KIND:
            r["occluded_mae_vs_limit"] = vs_limit(p.ao, scene)
    return [r for _, r in mine]


def peer_images(scene: Scene, rows: list[dict], images):
    """Encodes every peer of IMAGED_PEERS into ``images`` (compare's collector of a scene's
    images); yields (row, within the budget) for the grid: EEVEE, the Cycles rung with most
    samples within the budget (else the cheapest), and the scene's screen-space limit."""
    by_name = {r["method"]: r for r in rows if r["scene"] == scene.name}
    for p in scene.peers:
        if p.kind in IMAGED_PEERS and p.name in by_name:
            images.encode(by_name[p.name], p.ao)
    cycles = [p for p in scene.peers if p.kind == "cycles" and p.render_time_s is not None]
    fits = [p for p in cycles if p.render_time_s * 1000 <= images.budget]
    pick = max(fits, key=lambda p: p.entry.get("samples", 0)) if fits else (
        min(cycles, key=lambda p: p.render_time_s) if cycles else None)
    chosen = [p for p in scene.peers if p.kind == "eevee"] + ([pick] if pick else [])
    for p in chosen:
        if p.name in by_name:
            yield by_name[p.name], p is not pick or bool(fits)
    if scene.limit is not None and scene.limit.name in by_name:
        yield by_name[scene.limit.name], True


# ----------------------------------------------------------------------------------------
# rtao


def rtao_not_run_reason(e: BaseException) -> str:
    """Why rtao did not run on a scene, as results.json keeps it: a missing mesh said without
    its path (the run's command line says where; the results name no folder of the machine),
    any other reason (a mesh of another scene, a refused range) as it is."""
    if isinstance(e, FileNotFoundError):
        return ("no reference.mesh beside its G-buffer (`aolab mesh` exports one, "
                "docs/methods/rtao.md)")
    return str(e)


def _rtao_scene(scene: Scene, threads: int):
    """(the scene's ray scene, rtao's range check of it): its mesh (the file beside its
    reference.exr) loaded and its BVH built; ValueError where the range rule refuses the
    scene (docs/conventions.md, "Ranges"), checked before any rung is timed."""
    mesh = aolab.mesh_for_gbuffer(scene.g)
    rays_scene = aolab.ray_scene(mesh, scene.g, threads=threads)
    offsets = aolab.rtao_range(scene.g, rays_scene, radius=scene.radius, threads=threads)
    if offsets["refusal"]:
        raise ValueError(offsets["refusal"])
    return rays_scene, offsets


def rtao_rows(scene: Scene, ladder: tuple[int, ...], timing: Timing, images, info: dict,
              notes: list[str], bar=None):
    """Yields rtao's row at each rung of ``ladder`` (rays per pixel) as it is timed (like a
    method, by ``timing``) and scored, each offered to ``images``: the BVH is built once and
    timed apart, its time stated in each row's note and settings, not added to the rung's.
    A scene rtao cannot run on (no mesh, a refused range) gets a note in ``notes`` and its
    reason in ``info`` (the scene's entry of results.json's scenes), and no rows."""
    if not ladder:
        return
    threads = timing.threads
    try:
        rays_scene, offsets = _rtao_scene(scene, threads)
    except (ValueError, OSError) as e:
        notes.append(f"{scene.name}: rtao not run ({e})")
        info["rtao_not_run"] = rtao_not_run_reason(e)
        if bar is not None:
            bar.update(len(ladder))
        return
    if offsets["warning"]:
        notes.append(f"{scene.name}: {offsets['warning']}")
    build_ms = rays_scene.build_seconds * 1000.0
    bvh = {"triangles": rays_scene.triangles, "bvh_build_ms": build_ms}
    info["rtao"] = bvh
    info["rtao_offset"] = {k: offsets[k] for k in ("pixels", "warned", "largest_share_of_radius")}
    for rays in ladder:
        if bar is not None:
            bar.set_description(f"{scene.name}: rtao {rays} rays")
        with warnings.catch_warnings():   # noted above, once
            warnings.simplefilter("ignore", aolab.RtaoRangeWarning)
            ao, times = timed(lambda: aolab.rtao(scene.g, rays_scene, radius=scene.radius,
                                                 rays=rays, threads=threads),
                              timing.warmup, timing.repeat, timing.max_ms)
        row = make_row(scene, "rtao", "rtao", f"{rays} ray{'s' if rays != 1 else ''}",
                       preset="", settings={"rays": rays, **bvh}, threads=threads,
                       runs=len(times),
                       note=f"Embree BVH of {rays_scene.triangles} triangles built in "
                            f"{build_ms:.1f} ms, apart (not in the time)",
                       **time_fields("method", times))
        row["total_ms"] = row["method_ms"]
        score_row(scene, row, ao)
        row["occluded_mae_vs_limit"] = vs_limit(ao, scene)
        images.offer(row, ao)
        yield row
        if bar is not None:
            bar.update(1)


# ----------------------------------------------------------------------------------------
# The noise floor


def noise_floor(scene: Scene, rows: list[dict]) -> dict | None:
    """The reference's own noise floor (noise_floor_peer), per region, from its peer's row
    among ``rows``; None when unknown."""
    chosen = noise_floor_peer(scene.peers)
    if chosen is None:
        return None
    mine = {r["method"]: r for r in rows if r["scene"] == scene.name and "metrics" in r}
    peer, factor, source = chosen
    r = mine[peer.name]
    floor = {"source": source, "key": r["key"], "estimated": factor != 1.0,
             **{f"{reg}_mae": r["metrics"][reg]["mae"] * factor for reg in REGIONS}}
    if factor == 1.0:
        floor["all_ssim"] = r["metrics"]["all"]["ssim"]
    return floor
