"""What a run of plans prints on the terminal, the same whether the plans run in this process
(aolab.cycles.run) or on a cluster (aolab.cycles.cluster): a line per finished plan, the
progress of a render or of the cluster's jobs, and the line on an interrupt. Lines are made
here and printed by the run loops, which the commands call."""

from __future__ import annotations

from pathlib import Path

from .cache import count_cached
from .plan import Plan


def unit(plans: list[Plan]) -> str:
    """What the plans are, for a count: frames, scenes or references (a mix)."""
    framed = {p.frame is not None for p in plans}
    return "frames" if framed == {True} else "scenes" if framed == {False} else "references"


def result_line(plan: Plan, folder: Path, how: str, out) -> str:
    """The line printed for a finished plan: what, how (cached, rendered in ...), its last
    file and where it was copied."""
    what = plan.scene.name + ("" if plan.frame is None else f" frame {plan.frame}")
    return (f"{what}: {how} -> {plan.result_files(folder)[-1]}"
            + (f" (copied to {out})" if out else ""))


def jobs_line(plans: list[Plan], done: int, running: int) -> str:
    """The cluster's progress line: how many of ``plans`` are done, running and queued."""
    return (f"\r  {unit(plans)}: {done} of {len(plans)} done, {running} running, "
            f"{len(plans) - done - running} queued ")


def interrupted_line(done: int, plans: list[Plan], cache: Path, stopped: str = "") -> str:
    """The line printed on Ctrl-C: this run's count and the cache's as well (a render can
    finish between the last line printed and the interrupt, and frames of an earlier run are
    not rendered again), ``stopped`` saying what became of the running renders."""
    return (f"interrupted after {done} of {len(plans)} {unit(plans)} "
            f"({count_cached(cache, plans)} in the cache); {stopped}run the same command "
            "again to resume")
