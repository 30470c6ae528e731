"""Headless Chromium driven through the DevTools protocol over a pipe (--remote-debugging-pipe:
the browser reads commands on its fd 3 and writes replies and events on its fd 4, each a JSON
message ended by a NUL byte), with nothing but the standard library: the report's tests and
scripts/report_screenshot.py open report.html in it, read what the page holds, move the mouse
and take screenshots.

    with Browser() as b:
        b.open(path)
        b.evaluate("document.title")
        b.errors      # uncaught exceptions, console errors, failed loads
"""
from __future__ import annotations

import base64
import json
import os
import select
import shutil
import subprocess
import tempfile
import time
from pathlib import Path
import pytest


def chromium() -> str | None:
    """Debian's Chromium (scripts/install-deps.sh installs it), or None."""
    return shutil.which("chromium") or shutil.which("chromium-browser")


class BrowserError(RuntimeError):
    pass


class Browser:
    """One headless Chromium with one page; a context manager that ends the browser."""

    def __init__(self, width: int = 1500, height: int = 1000, timeout: float = 60.0):
        exe = chromium()
        if exe is None:
            raise BrowserError("Chromium is not installed")
        self.timeout = timeout
        self.profile = tempfile.mkdtemp(prefix="aolab-chromium-")
        to_browser_r, self._to_browser = os.pipe()
        self._from_browser, from_browser_w = os.pipe()

        def child_fds():   # the browser's fd 3 reads our commands, its fd 4 writes to us
            os.dup2(to_browser_r, 100)
            os.dup2(from_browser_w, 101)
            os.dup2(100, 3)
            os.dup2(101, 4)
            os.close(100)
            os.close(101)

        self._log = tempfile.TemporaryFile()   # (a pipe could fill and stall the browser)
        self.proc = subprocess.Popen(
            [exe, "--headless", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
             "--no-first-run", "--no-default-browser-check", "--disable-extensions",
             "--hide-scrollbars", "--remote-debugging-pipe", f"--user-data-dir={self.profile}",
             f"--window-size={width},{height}", "about:blank"],
            stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=self._log,
            close_fds=False, preexec_fn=child_fds)
        os.close(to_browser_r)
        os.close(from_browser_w)
        self._buffer = b""
        self._next_id = 0
        self.events: list[dict] = []
        self.session = None
        try:
            targets = self.call("Target.getTargets")["targetInfos"]
            page = next(t for t in targets if t["type"] == "page")
            self.session = self.call("Target.attachToTarget", targetId=page["targetId"],
                                     flatten=True)["sessionId"]
            for domain in ("Page", "Runtime", "Log"):
                self.call(f"{domain}.enable")
            self.call("Emulation.setDeviceMetricsOverride", width=width, height=height,
                      deviceScaleFactor=1, mobile=False)
        except Exception:
            self.close()
            raise

    # ---- the protocol ----

    def _send(self, message: dict) -> None:
        data = json.dumps(message).encode() + b"\0"
        while data:
            data = data[os.write(self._to_browser, data):]

    def _receive(self, deadline: float) -> dict:
        while b"\0" not in self._buffer:
            left = deadline - time.monotonic()
            if left <= 0 or not select.select([self._from_browser], [], [], left)[0]:
                raise BrowserError("Chromium did not answer in time")
            chunk = os.read(self._from_browser, 1 << 16)
            if not chunk:
                self._log.seek(0)
                raise BrowserError("Chromium closed the pipe: "
                                   + self._log.read().decode(errors="replace")[-2000:])
            self._buffer += chunk
        message, self._buffer = self._buffer.split(b"\0", 1)
        return json.loads(message)

    def call(self, method: str, **params) -> dict:
        """Sends a command (to the page once attached) and returns its result; the events
        that arrive meanwhile are kept in ``events``."""
        self._next_id += 1
        message = {"id": self._next_id, "method": method, "params": params}
        if self.session and not method.startswith(("Target.", "Browser.")):
            message["sessionId"] = self.session
        self._send(message)
        deadline = time.monotonic() + self.timeout
        while True:
            reply = self._receive(deadline)
            if reply.get("id") == self._next_id:
                if "error" in reply:
                    raise BrowserError(f"{method}: {reply['error']}")
                return reply.get("result", {})
            if "method" in reply:
                self.events.append(reply)

    def wait_for(self, event: str, timeout: float | None = None) -> dict:
        """The first kept or arriving event named ``event`` (removed from ``events``)."""
        deadline = time.monotonic() + (timeout or self.timeout)
        while True:
            for i, e in enumerate(self.events):
                if e["method"] == event:
                    return self.events.pop(i)
            reply = self._receive(deadline)
            if "method" in reply:
                self.events.append(reply)

    # ---- the page ----

    def open(self, path: Path) -> None:
        """Loads a file and waits for its load event."""
        self.events = [e for e in self.events if e["method"] != "Page.loadEventFired"]
        self.call("Page.navigate", url=Path(path).resolve().as_uri())
        self.wait_for("Page.loadEventFired")

    def evaluate(self, expression: str):
        """The value of a JavaScript expression in the page (a promise is awaited)."""
        got = self.call("Runtime.evaluate", expression=expression, awaitPromise=True,
                        returnByValue=True)
        if "exceptionDetails" in got:
            raise BrowserError(f"{expression[:80]}...: {got['exceptionDetails']}")
        return got["result"].get("value")

    def mouse(self, kind: str, x: float, y: float) -> None:
        """A mouse event at page coordinates: "mouseMoved", "mousePressed", "mouseReleased"
        (pressed and released with the left button)."""
        extra = {} if kind == "mouseMoved" else {"button": "left", "clickCount": 1}
        self.call("Input.dispatchMouseEvent", type=kind, x=x, y=y, **extra)

    def screenshot(self, path: Path, clip: dict | None = None) -> None:
        """A PNG of the viewport, or of ``clip`` ({x, y, width, height} in page pixels, in
        view)."""
        params = {"format": "png"}
        if clip:   # (within the viewport: capturing beyond it resizes the page, and a
            params["clip"] = {**clip, "scale": 1}   # resize ends plotly.js's hover)
        data = self.call("Page.captureScreenshot", **params)["data"]
        Path(path).write_bytes(base64.b64decode(data))

    @property
    def errors(self) -> list[str]:
        """What went wrong in the page so far: uncaught exceptions, console.error calls and
        error log entries (a file that failed to load, a script error)."""
        out = []
        for e in self.events:
            p = e.get("params", {})
            if e["method"] == "Runtime.exceptionThrown":
                d = p["exceptionDetails"]
                out.append("exception: " + (d.get("exception", {}).get("description")
                                            or d.get("text", "")))
            elif e["method"] == "Runtime.consoleAPICalled" and p.get("type") == "error":
                out.append("console.error: " + " ".join(str(a.get("value", a.get(
                    "description", ""))) for a in p.get("args", [])))
            elif e["method"] == "Log.entryAdded" and p["entry"].get("level") == "error":
                out.append(f'log: {p["entry"].get("text")} {p["entry"].get("url", "")}')
        return out

    def close(self) -> None:
        try:
            if self.proc.poll() is None:
                try:
                    self._send({"id": 0, "method": "Browser.close", "params": {}})
                    self.proc.wait(timeout=10)
                except (OSError, subprocess.TimeoutExpired):
                    self.proc.kill()
                    self.proc.wait()
        finally:
            for fd in (self._to_browser, self._from_browser):
                try:
                    os.close(fd)
                except OSError:
                    pass
            self._log.close()
            shutil.rmtree(self.profile, ignore_errors=True)

    def __enter__(self) -> "Browser":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


#: Pixels within which two points of a plot may both answer a hover (plotly.js's markers are
#: 8 px wide).
NEAR = 10


def poll(b: Browser, expression: str, timeout: float = 10.0):
    """The first truthy value of ``expression`` in the page, evaluated every 50 ms (the last
    value after ``timeout`` seconds)."""
    end = time.monotonic() + timeout
    while True:
        value = b.evaluate(expression)
        if value or time.monotonic() > end:
            return value
        time.sleep(0.05)


def plot_point(b: Browser, plot: str, name: str | None = None, key: str | None = None) -> dict:
    """A point of a plot of report.html (aolab.study.charts.plotly_figure), its plot scrolled
    into view: {"key", "x", "y" (page pixels), "d" (pixels to the nearest other point),
    "near" (the keys of the points within NEAR px, which a hover there may show instead)}.
    The point whose row is ``key``; else, of the trace ``name`` (else of every method's
    trace), the one farthest from every other point."""
    return b.evaluate(f"""(() => {{
        const gd = document.getElementById({json.dumps(plot)});
        gd.scrollIntoView({{block: 'center'}});
        const fl = gd._fullLayout, r = gd.getBoundingClientRect(), all = [];
        gd._fullData.forEach(t => {{
            if (!t.meta || t.meta.role !== 'series') return;
            t.x.forEach((x, j) => all.push({{name: t.name, kind: t.meta.kind,
                key: t.customdata[j], x: r.left + fl.xaxis._offset + fl.xaxis.c2p(x),
                y: r.top + fl.yaxis._offset + fl.yaxis.c2p(t.y[j])}}));
        }});
        const key = {json.dumps(key)}, name = {json.dumps(name)};
        const wanted = a => key ? a.key === key : name ? a.name === name : a.kind === 'method';
        let best = null;
        all.filter(wanted).forEach(a => {{
            const others = all.filter(o => o !== a);
            const dist = o => Math.hypot(o.x - a.x, o.y - a.y);
            const d = Math.min(...others.map(dist));
            if (!best || d > best.d)
                best = {{key: a.key, x: a.x, y: a.y, d: d,
                         near: others.filter(o => dist(o) < {NEAR}).map(o => o.key)}};
        }});
        return best;
    }})()""")


def need_chromium():
    if chromium() is None:
        pytest.skip("Chromium is not installed (Debian: apt-get install chromium; "
                    "scripts/install-deps.sh installs it)")
