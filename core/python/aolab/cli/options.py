"""Options several ``aolab`` commands share: --threads and the timing options, the cluster
options, --follow-symlinks and --crop. The value types themselves are in
aolab.util.arguments (the bridge's entry point inside Blender shares them)."""

from __future__ import annotations

from ..scenes import Crop
from ..util.arguments import MAX_RUNS, MAX_THREADS, int_option, parse_crop
from ..util.dask_cluster import (TLS_OPTIONS, ClusterSecurity, check_scheduler,
                                 parse_scheduler)


def add_follow_symlinks_option(q) -> None:
    """--follow-symlinks: read a scene's files through symbolic links (compare, tune, limits,
    reference, mesh, radius-study, rtao of a scene folder; docs/file_formats.md, "Scene
    folders: confined")."""
    q.add_argument("--follow-symlinks", action="store_true",
                   help="read a scene's files even where they are symbolic links (by default a "
                   "link among a scene's files is refused: its files must be regular files "
                   "inside its folder); each link followed is named on stderr")


def crop_of(text: str | None) -> Crop | None:
    """--crop of compare and tune (WxH: util.arguments.parse_crop) as the scenes.Crop they
    score, or None without one."""
    size = parse_crop(text)
    return None if size is None else Crop(*size)


def threads_option():
    return int_option("--threads", 0, MAX_THREADS, what="0 = all cores")


def add_timing_options(q, *, repeat: int, warmup: int, repeat_help: str = "timed runs",
                       warmup_help: str = "untimed runs before them") -> None:
    """--threads, --repeat and --warmup with their ranges (bench, compare, tune)."""
    q.add_argument("--threads", type=threads_option(), default=0,
                   help=f"worker threads, 0 to {MAX_THREADS} (0 = all cores)")
    q.add_argument("--repeat", type=int_option("--repeat", 1, MAX_RUNS), default=repeat,
                   help=f"{repeat_help}, 1 to {MAX_RUNS} (default {repeat})")
    q.add_argument("--warmup", type=int_option("--warmup", 0, MAX_RUNS), default=warmup,
                   help=f"{warmup_help}, 0 to {MAX_RUNS} (default {warmup})")


#: The most workers --workers starts on this machine.
MAX_WORKERS = 256


def add_cluster_options(q, verb: str, alone: str, needs: str) -> None:
    """--workers and --scheduler: a Dask cluster for the work (reference, tune, compare;
    docs/scale_out.md)."""
    q.add_argument("--workers", type=int_option("--workers", 1, MAX_WORKERS), default=1,
                   help=f"{verb} on a local Dask cluster of this many workers, 1 to "
                   f"{MAX_WORKERS} (default 1: in this process, {alone}; docs/scale_out.md)")
    q.add_argument("--scheduler", metavar="ADDRESS",
                   help=f"{verb} on the Dask cluster whose scheduler is at ADDRESS (e.g. "
                   f"tls://10.0.0.5:8786, with the three --tls options); its workers need "
                   f"{needs} (docs/scale_out.md)")
    q.add_argument("--tls-ca-file", metavar="FILE",
                   help="with a tls:// --scheduler: the CA certificate the farm's certificates "
                   "are signed by (PEM; default: Dask's configuration)")
    q.add_argument("--tls-cert", metavar="FILE",
                   help="with a tls:// --scheduler: this client's certificate (PEM)")
    q.add_argument("--tls-key", metavar="FILE",
                   help="with a tls:// --scheduler: this client's private key (PEM)")
    q.add_argument("--insecure", action="store_true",
                   help="allow a plain tcp:// --scheduler beyond this machine: anyone who "
                   "reaches its port can run code on every worker (docs/scale_out.md, "
                   "\"Security\")")


def cluster_security(args):
    """The --tls-* and --insecure options as a ClusterSecurity, checked with --scheduler
    before any work starts (a ValueError naming the option)."""
    security = ClusterSecurity(ca_file=args.tls_ca_file, cert=args.tls_cert, key=args.tls_key,
                               insecure=args.insecure)
    if args.scheduler is not None:   # "" too: refused, never taken for no scheduler
        check_scheduler(args.scheduler, security, warn=False)   # connect() warns
    given = {o: v for o, v in zip(TLS_OPTIONS, (args.tls_ca_file, args.tls_cert, args.tls_key))
             if v is not None}
    if given and (args.scheduler is None or parse_scheduler(args.scheduler).scheme != "tls"):
        option = next(iter(given))   # never silently ignored
        where = "none is given" if args.scheduler is None else f"{args.scheduler!r} is not one"
        raise ValueError(f"{option} {given[option]!r}: only a tls:// --scheduler uses it, "
                         f"and {where}")
    return security
