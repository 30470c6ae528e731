"""How the studies time a computation (docs/comparison.md, "Timing protocol"): warm-up
runs, then the median of the timed runs, with their spread as row fields. Used by `aolab
compare`, its temporal accumulation and the radius study."""

from __future__ import annotations

import math
import statistics
import time


def timed(fn, warmup: int, repeat: int, max_ms: float = math.inf):
    """Runs ``fn`` warmup + repeat times; returns (first output, times of the timed runs in ms).
    The output of the first run is kept (the methods are deterministic). A first run longer
    than ``max_ms`` is the only one, and its time is the time (as aolab tune does): past a
    second, a warm-up changes the time by far less than the run-to-run spread."""
    result, times = None, []
    for i in range(warmup + repeat):
        t0 = time.perf_counter()
        out = fn()
        dt = (time.perf_counter() - t0) * 1000.0
        if result is None:
            result = out
            if dt > max_ms:
                return result, [dt]
        if i >= warmup:
            times.append(dt)
    return result, times


def time_fields(prefix: str, times: list[float]) -> dict:
    """A row's fields of ``times`` (ms): <prefix>_ms (the median), _ms_min and _ms_max, and
    for the method its standard deviation; none without times."""
    if not times:
        return {}
    out = {f"{prefix}_ms": statistics.median(times), f"{prefix}_ms_min": min(times),
           f"{prefix}_ms_max": max(times)}
    if prefix == "method":
        out["method_ms_stdev"] = statistics.stdev(times) if len(times) > 1 else 0.0
    return out
