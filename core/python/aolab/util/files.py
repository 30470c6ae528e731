"""Files: the one way the ``aolab`` package reads, writes and owns files (docs/conventions.md,
"Files").

- **Reading**: :func:`regular_file` checks a path before anything opens or hashes it, so a
  FIFO never blocks a reader and a folder never gives a reader's obscure error;
  :func:`read_bytes` reads a file so checked.
- **Writing**: :func:`write_bytes`, :func:`write_text` and :func:`write_together` go through
  the core's durable write (core/io/files.h): a temporary file beside the target, every write
  checked, fsync, close checked, rename, the folder synced. A full disk raises OSError and
  leaves the earlier file and no temporary behind.
- **Checking before work**: :func:`check_output_file` and :func:`check_output_folder` refuse an
  output path that cannot be written before a long computation starts; :func:`check_distinct`
  refuses an output that is one of the command's inputs or another of its outputs (real
  paths, after symbolic links); :func:`check_paths` does both for a command's options.
- **Owning a folder**: :func:`output_lock` lets one run at a time write into an output folder.
- **Checksums**: :func:`write_checksums` records the SHA-256 and size of a folder's files in
  its ``SHA256SUMS`` (sha256sum's format); :func:`checksum_mismatch` says which file no longer
  matches, so that a changed or damaged file is never used as it was.
- **Names from the user's strings**: :func:`file_name_for` is the one way a file name is made
  from a scene, sequence or configuration name: bounded, safe, and distinct per name.
- **Confined folders**: :func:`first_symlink` finds a symbolic link among a folder's files, so
  that a caller refuses it before anything is read through it.

Nothing here imports another ``aolab`` module but the compiled core, so every layer (the
bridge inside Blender included) can use it.
"""

from __future__ import annotations

import contextlib
import errno
import fcntl
import hashlib
import json
import os
import re
import stat
from pathlib import Path

from .. import _core

#: The lock file :func:`output_lock` keeps in an output folder (hidden; it holds the owner).
LOCK_NAME = ".aolab.lock"
#: The file :func:`write_checksums` writes into a folder: ``<sha256>  <name>`` per line, as
#: ``sha256sum`` writes and ``sha256sum -c`` checks.
CHECKSUMS_NAME = "SHA256SUMS"


#: The longest name :func:`file_name_for` returns (the callers add at most some 40 characters
#: of their own, well below the 255 bytes a file name may have).
MAX_NAME_CHARS = 64
#: The hex digits of the SHA-256 of the full name that :func:`file_name_for` appends to a name
#: it had to shorten or change.
NAME_HASH_CHARS = 10
_UNSAFE_IN_NAME = re.compile(r"[^A-Za-z0-9_.-]+")


class FolderInUse(OSError):
    """Another run holds the output folder (:func:`output_lock`); errno EBUSY."""


def _kind(mode: int) -> str:
    return ("a folder" if stat.S_ISDIR(mode) else
            "a regular file" if stat.S_ISREG(mode) else
            "a FIFO (named pipe)" if stat.S_ISFIFO(mode) else
            "a socket" if stat.S_ISSOCK(mode) else "a device or special file")


def regular_file(spec, what: str) -> Path:
    """``spec`` as a Path after checking, without opening it, that it is a regular file: a
    missing file is FileNotFoundError naming ``what``; a folder, a FIFO, a socket or a device
    is a ValueError saying which it is (opening a FIFO would wait forever)."""
    try:
        st = os.stat(spec)
    except FileNotFoundError:
        raise FileNotFoundError(errno.ENOENT, f"no such {what} file", str(spec)) from None
    except NotADirectoryError:
        raise ValueError(f"no such {what} file: {spec} (a part of the path is a file, not a "
                         "folder)") from None
    if not stat.S_ISREG(st.st_mode):
        raise ValueError(f"{what} must be a regular file, got {str(spec)!r}, which is "
                         f"{_kind(st.st_mode)}")
    return Path(spec)


def read_bytes(spec, what: str) -> bytes:
    """The bytes of the regular file ``spec`` (:func:`regular_file`'s errors)."""
    return regular_file(spec, what).read_bytes()


def read_text(spec, what: str) -> str:
    """The UTF-8 text of the regular file ``spec``; a file that is not UTF-8 is a ValueError
    naming it."""
    return _decoded(read_bytes(spec, what), spec, what)


def _decoded(data: bytes, spec, what: str) -> str:
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as e:
        raise ValueError(f"{what} file {spec} is not UTF-8 text ({e})") from None


def json_object(data: bytes, spec, what: str) -> dict:
    """The JSON object in ``data``, the bytes of the file ``spec`` (for a caller that needs
    the bytes too, e.g. to hash them); anything else is a ValueError naming the file."""
    try:
        value = json.loads(_decoded(data, spec, what))
    except json.JSONDecodeError as e:
        raise ValueError(f"{what} file {spec} is not valid JSON ({e})") from None
    if not isinstance(value, dict):
        raise ValueError(f"{what} file {spec} must hold a JSON object, got "
                         f"{type(value).__name__}")
    return value


def write_bytes(path, data: bytes) -> None:
    """Replaces ``path`` by ``data``, durably and atomically (the module's docstring); the
    folder must exist. OSError when the write fails, the earlier file kept."""
    _core.write_file_durably(os.fspath(path), bytes(data))


def write_text(path, text: str) -> None:
    """:func:`write_bytes` of ``text`` in UTF-8."""
    write_bytes(path, text.encode("utf-8"))


def write_together(files: list[tuple[object, bytes]]) -> None:
    """Files that belong together ([(path, bytes), ...]): all written and synced before any is
    renamed into place, so a failure never leaves a new file beside a stale partner."""
    _core.write_files_durably([(os.fspath(p), bytes(d)) for p, d in files])


def check_output_file(path, what: str) -> Path:
    """Checks, before any work, that ``path`` can receive a file: its folder exists and is a
    folder we may write in, and ``path`` is not a folder or special file. Returns it as a
    Path; a ValueError naming ``what`` otherwise."""
    p = Path(path)
    # Path() drops a trailing slash, which says the user meant a folder.
    if p.name in ("", ".", "..") or str(path).endswith(("/", os.sep)):
        raise ValueError(f"{what} must name a file, got {str(path)!r}")
    _check_writable_folder(p.parent if str(p.parent) else Path("."), what, str(path))
    try:
        st = os.stat(p)
    except FileNotFoundError:
        return p
    except OSError as e:
        raise ValueError(f"{what} {str(path)!r} cannot be checked: {e.strerror}") from None
    if not stat.S_ISREG(st.st_mode):
        raise ValueError(f"{what} must be a file, got {str(path)!r}, which is "
                         f"{_kind(st.st_mode)}")
    return p


def check_output_folder(path, what: str) -> Path:
    """Checks, before any work, that ``path`` is a folder or can be made one: nothing but a
    folder is there, and the nearest existing ancestor is a folder we may write in. Returns
    it as a Path; a ValueError naming ``what`` otherwise."""
    p = Path(path)
    if p.exists() and not p.is_dir():
        raise ValueError(f"{what} must be a folder, got {str(path)!r}, which is "
                         f"{_kind(os.stat(p).st_mode)}")
    existing = p
    while not existing.exists():
        if existing.is_symlink():
            raise ValueError(f"{what} {str(path)!r}: {existing} is a broken symbolic link")
        existing = existing.parent
    if not existing.is_dir():
        raise ValueError(f"{what} {str(path)!r} cannot be made: {existing} is a file, not a "
                         "folder")
    _check_writable_folder(existing, what, str(path))
    return p


def check_name_fits(path, name: str, what: str) -> None:
    """Checks, before any work, that a file named ``name`` can be made in the folder ``path``
    (or where it will be made): the file system there takes names that long. A ValueError
    naming ``what`` otherwise."""
    existing = Path(path)
    while not existing.is_dir() and existing != existing.parent:
        existing = existing.parent
    try:
        most = os.pathconf(existing, "PC_NAME_MAX")
    except (OSError, ValueError):   # no limit known: nothing to check
        return
    if len(name.encode("utf-8", "surrogatepass")) > most:
        raise ValueError(f"{what} {str(path)!r}: its file system takes file names of at most "
                         f"{most} bytes, and the output needs {name!r}")


def _check_writable_folder(folder: Path, what: str, spec: str) -> None:
    if not folder.is_dir():
        raise ValueError(f"{what} {spec!r}: the folder {folder} does not exist")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise ValueError(f"{what} {spec!r}: the folder {folder} is not writable")


@contextlib.contextmanager
def output_lock(folder, owner: str):
    """Holds ``folder`` (made if missing) for one run: a second run that asks for it while
    this one holds it gets FolderInUse naming the holder, at once, instead of mixing its
    files with this run's. The lock is the kernel's (flock on ``folder/.aolab.lock``), so it
    ends with the process however the process ends; the lock file is removed when the run
    ends, and so is a folder this call made that the run left empty."""
    folder = Path(folder)
    made = not folder.exists()
    folder.mkdir(parents=True, exist_ok=True)
    lock = folder / LOCK_NAME
    fd = _locked(lock, owner)
    try:
        yield folder
    finally:
        lock.unlink(missing_ok=True)   # while still held: see _locked
        os.close(fd)
        if made and not any(folder.iterdir()):
            folder.rmdir()


def _locked(lock: Path, owner: str) -> int:
    """An open descriptor of ``lock`` holding its flock, with ``owner`` written in it. A
    holder unlinks the file before it lets go, so a lock taken on a file that is no longer
    at ``lock`` is stale and taken again on the new one."""
    while True:
        fd = os.open(lock, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o644)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = os.pread(fd, 500, 0).decode("utf-8", "replace").strip() or "another run"
            os.close(fd)
            raise FolderInUse(errno.EBUSY, f"output folder in use by {holder}: wait for it to "
                              "finish or choose another output folder", str(lock.parent)) from None
        try:
            same = os.stat(lock).st_ino == os.fstat(fd).st_ino
        except FileNotFoundError:
            same = False
        if same:
            os.ftruncate(fd, 0)
            os.pwrite(fd, f"{owner} (pid {os.getpid()})\n".encode(), 0)
            return fd
        os.close(fd)


def check_paths(*, files: dict = {}, folders: dict = {}, edited: dict = {},
                inputs: dict = {}, reads: dict = {}, made: dict = {},
                cleared: dict = {}) -> None:
    """Checks, before a command's work starts, the paths its options name ({option: path};
    an option left unset is skipped), so that a mistyped path costs no hours of work: an
    output file (``files``: its folder exists and is writable, the path is no folder or
    special file; a list of paths for an option that writes several, such as --out's
    OUT.exr and OUT.png), an output folder (``folders``: a folder, or one that can be made),
    a file rewritten in place (``edited``: an existing regular file that can be replaced),
    an input folder (``inputs``: an existing folder). A ValueError naming the option
    otherwise. Then :func:`check_distinct`: no output (those above, and ``made``: files in a
    folder the command makes later) is an input (``reads``, ``inputs``) or another output,
    and no input lies in a folder the command clears (``cleared``)."""
    for option, path in files.items():
        for p in _listed(path):
            check_output_file(p, option)
    for option, path in folders.items():
        if path:
            check_output_folder(path, option)
    for option, path in edited.items():
        if path:
            regular_file(path, option)
            check_output_file(path, option)
    for option, path in inputs.items():
        if path and not Path(path).is_dir():
            what = "does not exist" if not os.path.lexists(path) else "is not a folder"
            raise ValueError(f"{option} must be an existing folder, got {str(path)!r}, which "
                             f"{what}")
    check_distinct(reads={**reads, **inputs}, writes={**made, **edited, **files},
                   cleared=cleared)


def _listed(value) -> list:
    """A path, or a list of paths, as a list without the unset ones."""
    return [p for p in (value if isinstance(value, (list, tuple)) else [value]) if p]


def _named(paths: dict, own: bool = False) -> list[tuple[str, str]]:
    """(what, real path) of each path of {label: path or [paths]}: ``label path``, or with
    ``own`` (an option's outputs) ``label's path`` for one of several (--out's y.exr)."""
    out = []
    for label, value in paths.items():
        mark = "'s" if own and isinstance(value, (list, tuple)) else ""
        out.extend((f"{label}{mark} {p}", real_path(p)) for p in _listed(value))
    return out


def real_path(path) -> str:
    """``path`` after every symbolic link, made absolute; for a path that does not exist
    yet, its existing folder's real path joined with the rest. Two paths with the same real
    path are the same file."""
    return os.path.realpath(os.fspath(path))


def _inside(path: str, folder: str) -> bool:
    return path == folder or path.startswith(folder.rstrip(os.sep) + os.sep)


def check_distinct(*, reads: dict = {}, writes: dict = {}, cleared: dict = {}) -> None:
    """Refuses, before any work, a command whose outputs would destroy what it reads or
    what it writes itself, comparing real paths (after symbolic links): an output
    (``writes``: {option: path or [paths]}) that is an input (``reads``: {label: path or
    [paths]}, files or folders) or another output, and a folder the command empties or
    replaces (``cleared``: {option: folder}) that is or holds an input.
    A ValueError naming both paths."""
    inputs = _named(reads)
    seen: list[tuple[str, str]] = []
    for what, real in _named(writes, own=True):
        for other, other_real in inputs:
            if real == other_real:
                raise ValueError(f"{what} is {other}: an output would overwrite an input")
        for other, other_real in seen:
            if real == other_real:
                raise ValueError(f"{what} is also written as {other}")
        seen.append((what, real))
    for what, real in _named(cleared):
        for other, other_real in inputs:
            if _inside(other_real, real):
                raise ValueError(f"{what} is cleared by this command and {other} is in "
                                 "it: an output would destroy an input")


def sha256_file(path) -> str:
    """The SHA-256 of a regular file (checked by :func:`regular_file`), in hex."""
    h = hashlib.sha256()
    with open(regular_file(path, "checksummed file"), "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def write_checksums(folder, names: list[str]) -> None:
    """Records the SHA-256 of ``folder``'s files ``names`` in ``folder/SHA256SUMS``
    (atomically)."""
    folder = Path(folder)
    write_text(folder / CHECKSUMS_NAME,
               "".join(f"{sha256_file(folder / n)}  {n}\n" for n in sorted(names)))


def read_checksums(folder) -> dict[str, str] | None:
    """``folder``'s SHA256SUMS as {name: sha256}, or None when it has none. A line that is
    not ``<64 hex digits>  <name>``, or whose name is not a plain file name of the folder
    (plain_name), is a ValueError naming the file and the line."""
    path = Path(folder) / CHECKSUMS_NAME
    if not path.exists():
        return None
    out = {}
    for number, line in enumerate(read_text(path, "checksums").splitlines(), 1):
        digest, sep, name = line.partition("  ")
        if not sep or len(digest) != 64 or not all(c in "0123456789abcdef" for c in digest):
            raise ValueError(f"{path}: line {number}: not a SHA256SUMS line: {line!r}")
        if not plain_name(name):
            raise ValueError(f"{path}: line {number}: {name!r} is not the plain name of a file "
                             "in this folder (no '/', '\\', '.' or '..', nothing hidden)")
        out[name] = digest
    return out


def plain_name(name: str) -> bool:
    """Whether ``name`` names a file of the folder itself: not empty, no ``/``, no ``\\``
    (sha256sum escapes names with a newline or a backslash by a ``\\`` at the line's start),
    not ``.`` or ``..``, not hidden (the lock file), no control character."""
    return bool(name) and not name.startswith(".") and "/" not in name and "\\" not in name \
        and all(c >= " " and c != "\x7f" for c in name)


def file_name_for(name: str) -> str:
    """The one file name made from a user's string ``name`` (a scene, sequence or
    configuration name): ``name`` itself when it is at most MAX_NAME_CHARS of letters,
    digits, ``_``, ``.`` and ``-`` and starts with neither ``.`` nor ``-``; otherwise a
    readable prefix (each run of other characters made ``_``) and ``-`` and the first
    NAME_HASH_CHARS hex digits of the SHA-256 of the whole name, so that two names never
    share a file. Never longer than MAX_NAME_CHARS, never ``.``, ``..``, hidden or a path."""
    name = str(name)
    plain = _UNSAFE_IN_NAME.sub("_", name)
    if plain == name and len(name) <= MAX_NAME_CHARS and name[:1] not in ("", ".", "-"):
        return name
    digest = hashlib.sha256(name.encode("utf-8", "surrogatepass")).hexdigest()
    prefix = plain.lstrip("._-")[:MAX_NAME_CHARS - NAME_HASH_CHARS - 1] or "name"
    return f"{prefix}-{digest[:NAME_HASH_CHARS]}"


def first_symlink(folder) -> Path | None:
    """The first symbolic link among ``folder``'s files and subfolders, at any depth (in
    sorted order; a link is not followed), or None. ``folder`` itself may be a link."""
    for top, dirs, names in os.walk(folder):
        dirs.sort()
        for name in sorted(dirs + names):
            if os.path.islink(os.path.join(top, name)):
                return Path(top) / name
    return None


def checksum_mismatch(folder, names: list[str]) -> str | None:
    """Why ``folder``'s files ``names`` do not match its SHA256SUMS ("reference.exr: SHA-256
    a1b2… recorded, c3d4… now"), or None when each is recorded and matches and every file
    recorded is there. A folder without SHA256SUMS is a mismatch too."""
    try:
        recorded = read_checksums(folder)
    except (OSError, ValueError) as e:
        return str(e)
    if recorded is None:
        return f"no {CHECKSUMS_NAME}"
    for name in sorted(set(names) | set(recorded)):
        if name not in recorded:
            return f"{name}: not in {CHECKSUMS_NAME}"
        try:
            now = sha256_file(Path(folder) / name)
        except OSError as e:
            return f"{name}: {e}"
        if now != recorded[name]:
            return (f"{name}: SHA-256 {recorded[name][:12]}… recorded, {now[:12]}… now")
    return None
