"""The repository explains itself.

- No file in it refers to a file outside it (a briefing document, a folder beside the
  checkout, an absolute path of the machine it was written on) or to a numbered issue of a
  tracker: a reader of a clone has neither, so each such reference must become a citation of
  a document inside the repository, or of a paper by title, authors, venue and section.
- Every relative Markdown link (README.md, docs/, every other .md) points at a file that
  exists, and a link with an anchor at a heading that exists; every path of the repository
  that a Markdown file names (`core/...`, `tests/...`, `docs/...`, ...) exists.
- core/aolab.h includes every public header of the core, and the core's folders include
  each other only in the order of its layers.

The files scanned are git's: tracked ones and new ones not ignored (`git ls-files -co
--exclude-standard`), so a file is checked before it is committed. This test reads files
only; it does not import aolab.
"""
from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]

# Files that are not text (images, renders, scenes); anything else holding a NUL byte is
# skipped too.
BINARY_SUFFIXES = {".exr", ".png", ".jpg", ".jpeg", ".gif", ".blend", ".glb", ".gltf", ".bin",
                   ".pdf", ".zip", ".gz", ".xz", ".npy", ".npz", ".so", ".o", ".a", ".pyc"}

# References to files outside the repository. The patterns are assembled from pieces so that
# this file does not match them itself.
OUTSIDE = [
    ("a briefing folder beside the checkout", re.compile(re.escape(".." + "/shared"))),
    ("the briefing's papers folder", re.compile(re.escape("shared" + "/papers"))),
    ("the briefing's design document", re.compile(r"\b" + "DESIGN" + r"\.md\b")),
    ("the briefing's Blender measurements", re.compile(r"\b" + "BLENDER" + "_FACTS")),
    ("the briefing's style notes", re.compile(r"\b" + "STYLE" + r"\.md\b")),
    ("an absolute path of the machine it was written on", re.compile(re.escape("/" + "work/"))),
]

# References to numbered issues: the word issue (or Issue, issues) followed by a number, with
# or without '#', and a '#' number standing alone (after a space or a bracket). A CSS colour
# such as `fill:#888` or `color: #555` is not an issue: a '#' number right after a colon is
# skipped.
ISSUE_WORD = re.compile(r"\b[Ii]ssues?\s*#?\s*\d+")
ISSUE_HASH = re.compile(r"(?:^|(?<=[\s(\[]))#\d+\b(?![0-9A-Za-z])")

# [text](target), ![alt](target), [text](<target> "title"); the text may hold one level of [].
MARKDOWN_LINK = re.compile(r"!?\[(?:[^\]\[]|\[[^\]]*\])*\]"
                           r"\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
FENCE = re.compile(r"^\s*(```|~~~)")
INLINE_CODE = re.compile(r"`+[^`]*`+")


def repository_files() -> list[Path]:
    out = subprocess.run(["git", "ls-files", "-co", "--exclude-standard", "-z"], cwd=ROOT,
                         capture_output=True, check=True).stdout.decode()
    return sorted({ROOT / name for name in out.split("\0") if name and (ROOT / name).is_file()})


def text_of(path: Path) -> str | None:
    """The file's text, or None for a binary file."""
    if path.suffix.lower() in BINARY_SUFFIXES:
        return None
    data = path.read_bytes()
    if b"\0" in data[:8192]:
        return None
    return data.decode("utf-8", errors="replace")


FILES = repository_files()
TEXTS = {p: t for p in FILES if (t := text_of(p)) is not None}
MARKDOWN = [p for p in TEXTS if p.suffix.lower() == ".md"]


def rel(path: Path) -> str:
    return path.relative_to(ROOT).as_posix()


def issue_references(line: str) -> list[str]:
    found = [m.group(0) for m in ISSUE_WORD.finditer(line)]
    for m in ISSUE_HASH.finditer(line):
        before = line[:m.start()].rstrip()
        if before.endswith(":"):  # a CSS colour, `color: #555`
            continue
        found.append(m.group(0))
    return found


def test_the_scan_sees_the_repository():
    names = {rel(p) for p in TEXTS}
    assert {"README.md", "docs/README.md", "CMakeLists.txt", "core/aolab.h"} <= names
    assert not any(n.endswith(".exr") for n in names)


def test_the_patterns_catch_what_they_should_and_nothing_else():
    # Assembled from pieces, so that neither this file nor a grep of it matches them.
    bad = ["see ../" + "sha" + "red/" + "BLEN" + "DER_FACTS.md", "(sha" + "red/pa" + "pers/x.md)",
           "DES" + "IGN.md \"Effects\"", "STY" + "LE.md", '"source": "/' + 'work/main/x.py"']
    for text in bad:
        assert any(p.search(text) for _, p in OUTSIDE), text
    for text in ["iss" + "ue 6 it" + "ems 4–6", "Iss" + "ue 4's acceptance", "(iss" + "ue 7)",
                 "issues " + "#" + "3 and", "fixed in " + "#12", "(" + "#7)"]:
        assert issue_references(text), text
    for text in ["svg .frame{fill:none;stroke:#888}", ".meta td{color: #666}", "# 1 comment",
                 "no static-initialisation order issues here", "a shared blur", "x#1",
                 "std::vector<int> v; // #include <x>", "DESIGNS.md.bak is not it"]:
        assert not issue_references(text) and not any(p.search(text) for _, p in OUTSIDE), text


def test_no_file_refers_outside_the_repository_or_to_an_issue():
    problems = []
    for path, text in TEXTS.items():
        for number, line in enumerate(text.splitlines(), 1):
            for what, pattern in OUTSIDE:
                if pattern.search(line):
                    problems.append(f"{rel(path)}:{number}: {what}: {line.strip()[:120]}")
            for ref in issue_references(line):
                problems.append(f"{rel(path)}:{number}: an issue number ({ref!r}): "
                                f"{line.strip()[:120]}")
    assert not problems, ("references a reader of the repository cannot follow (cite a file of "
                          "the repository, or a paper by title, authors, venue and section):\n"
                          + "\n".join(problems))


def slug(heading: str) -> str:
    """GitHub's anchor for a Markdown heading: links reduced to their text, lower case, every
    character but letters, digits, '_', '-' and spaces dropped, spaces turned into '-'."""
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", heading).strip().lower()
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def anchors(text: str) -> set[str]:
    found, seen = set(), {}
    in_fence = False
    for line in text.splitlines():
        if FENCE.match(line):
            in_fence = not in_fence
            continue
        if in_fence:
            continue
        m = re.match(r"^\s{0,3}(#{1,6})\s+(.*?)\s*#*\s*$", line)
        if m:
            base = slug(m.group(2))
            n = seen.get(base, 0)
            seen[base] = n + 1
            found.add(base if n == 0 else f"{base}-{n}")
        found.update(re.findall(r"<a\s+(?:id|name)=\"([^\"]+)\"", line))
    return found


def links(text: str):
    """(line number, target) of every Markdown link outside code."""
    in_fence = False
    for number, line in enumerate(text.splitlines(), 1):
        if FENCE.match(line):
            in_fence = not in_fence
            continue
        if in_fence:
            continue
        for m in MARKDOWN_LINK.finditer(INLINE_CODE.sub("", line)):
            yield number, m.group(1)


def test_markdown_links_point_at_files_and_headings_that_exist():
    assert {"README.md", "docs/README.md"} <= {rel(p) for p in MARKDOWN}
    problems, checked = [], 0
    for path in MARKDOWN:
        for number, target in links(TEXTS[path]):
            if re.match(r"^[a-z][a-z0-9+.-]*:", target, re.I):  # http:, https:, mailto:
                continue
            checked += 1
            where, _, anchor = target.partition("#")
            dest = (path.parent / where).resolve() if where else path
            if ROOT not in dest.parents and dest != ROOT:
                problems.append(f"{rel(path)}:{number}: {target} leaves the repository")
                continue
            if not dest.exists():
                problems.append(f"{rel(path)}:{number}: {target}: no such file")
                continue
            if anchor and dest.suffix.lower() == ".md" and dest.is_file():
                if anchor not in anchors(dest.read_text()):
                    problems.append(f"{rel(path)}:{number}: {target}: no heading "
                                    f"'{anchor}' in {rel(dest)}")
    assert checked > 50, f"only {checked} links found: the link pattern is broken"
    assert not problems, "broken Markdown links:\n" + "\n".join(problems)


# A path of the repository named in prose: it starts with one of the top folders. One followed
# by a placeholder (`methods/<name>.md`, `results_*.svg`, `registry.{h,cpp}`) is a pattern.
NAMED_PATH = re.compile(r"(?<![\w/.-])((?:core|tests|scripts|blender_addon|reference_scenes|docs)"
                        r"/[\w./-]*\w)")


def test_paths_named_in_markdown_exist():
    problems, checked = [], 0
    for path in MARKDOWN:
        for number, line in enumerate(TEXTS[path].splitlines(), 1):
            for m in NAMED_PATH.finditer(line):
                after = line[m.end():m.end() + 2]
                if after[:1] in ("<", "*", "{", "…") or after == ".{":
                    continue
                checked += 1
                if not (ROOT / m.group(1)).exists():
                    problems.append(f"{rel(path)}:{number}: {m.group(1)}: no such file or folder")
    assert checked > 100, f"only {checked} paths found: the path pattern is broken"
    assert not problems, "paths named in the documentation that do not exist:\n" + \
        "\n".join(problems)


def public_core_headers() -> set[str]:
    """Every header of the core (core/python/ aside), except a method's private helpers (in
    core/methods/<name>/ only <name>.h is public) and Highway's per-target *-inl.h headers,
    which only a kernel's own foreach_target pass includes."""
    out = set()
    for path in FILES:
        name = rel(path)
        if not name.startswith("core/") or not name.endswith(".h") or name == "core/aolab.h":
            continue
        if name.startswith("core/python/") or name.endswith("-inl.h"):
            continue
        parts = name.split("/")
        if len(parts) == 4 and parts[1] == "methods" and parts[3] != parts[2] + ".h":
            continue
        out.add(name)
    return out


def test_the_umbrella_header_includes_every_public_header():
    text = (ROOT / "core" / "aolab.h").read_text()
    included = set(re.findall(r'^#include "([^"]+)"', text, re.M))
    missing = sorted(public_core_headers() - included)
    assert not missing, f"core/aolab.h does not include {missing}"
    assert not [h for h in included if not (ROOT / h).is_file()], included


# The core's layers (docs/architecture.md): base/ uses nothing else; the folders of the middle
# layer use base/ and themselves; the libraries that methods share (horizon/: the receiver,
# directions, tangent test, slice and obscurance estimator of the horizon-based methods;
# volumetric/: the pipes of VAO and VAO++) use base/, sampling/ and themselves; a method's
# folder uses its own files, base/, sampling/, filters/, those libraries and the registry
# (registry.h), never another method's folder; the registry includes every method's public
# header. raytracing/ (rtao, not a method) uses base/, sampling/ and itself, not methods/.
MIDDLE = {"sampling", "io", "scoring", "filters", "scenes"}
SHARED_LIBRARIES = {"horizon", "volumetric"}
METHOD_MAY_USE = {"base", "sampling", "filters"} | SHARED_LIBRARIES


def allowed_include(source: str, header: str) -> bool:
    src, dst = source.split("/"), header.split("/")
    if src[1] == "base":
        return dst[1] == "base"
    if src[1] in MIDDLE:
        return dst[1] in ("base", src[1])
    if src[1] in SHARED_LIBRARIES:
        return dst[1] in ("base", "sampling", src[1])
    if src[1] == "raytracing":
        return dst[1] in ("base", "sampling", "raytracing")
    if src[1] == "methods":
        if dst[1] != "methods":
            return dst[1] in METHOD_MAY_USE
        if len(dst) == 3:  # core/methods/registry.h
            return True
        if len(src) == 3:  # the registry: every method's public header, no private helper
            return dst[3] == dst[2] + ".h"
        return dst[2] == src[2]  # its own folder, never another method's
    return True  # core/aolab.h


def test_core_layers_include_only_what_they_may():
    problems = []
    for path, text in TEXTS.items():
        name = rel(path)
        if not name.startswith("core/") or name.startswith("core/python/") or \
                path.suffix not in (".h", ".cpp"):
            continue
        for header in re.findall(r'^\s*#\s*include\s*[<"]([^>"]+)[>"]', text, re.M):
            if re.match(r"(pybind11/|Python\.h$|bpy)", header):
                problems.append(f"{name}: includes {header}: the core knows nothing of Python")
            elif header.startswith("core/") and not allowed_include(name, header):
                problems.append(f"{name}: includes {header}, against the layers")
    assert not problems, "\n".join(problems)


@pytest.mark.parametrize("name", ["README.md", "docs/README.md"])
def test_the_architecture_page_is_linked(name):
    assert "architecture.md" in (ROOT / name).read_text()


def test_the_size_check_finds_a_long_module_and_a_long_function(tmp_path):
    """scripts/check_sizes.py (run by scripts/lint.sh) names what is over its limits, and
    nothing else; the package itself passes it."""
    import importlib.util
    spec = importlib.util.spec_from_file_location("check_sizes", ROOT / "scripts/check_sizes.py")
    sizes = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(sizes)
    package = tmp_path / "core" / "python" / "aolab"
    package.mkdir(parents=True)
    body = "\n".join(f"    x{i} = {i}" for i in range(sizes.MAX_FUNCTION_LINES - 1))
    (package / "short.py").write_text(f"def fits():\n{body}\n")
    (package / "long.py").write_text(f"def too_long():\n{body}\n    return 0\n"
                                     + "\n" * sizes.MAX_MODULE_LINES)
    found = sizes.breaches(package)
    assert len(found) == 2, found
    assert f"too_long is {sizes.MAX_FUNCTION_LINES + 1} lines" in found[0] + found[1]
    assert any("long.py:" in f and "lines >" in f and "too_long" not in f for f in found)
    assert sizes.breaches() == [], "\n".join(sizes.breaches())
