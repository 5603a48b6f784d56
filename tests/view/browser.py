"""Headless Chromium driven over the DevTools protocol: load a page, take screenshots.

One browser serves several screenshots (its start-up costs seconds). Chromium is
Debian's ``chromium`` package (``.ci/run`` installs it for CI; the test set-up does not);
:func:`find_chromium` returns ``None`` when there is none, and the tests skip.
"""

from __future__ import annotations

import base64
import contextlib
import io
import itertools
import json
import os
import shutil
import signal
import subprocess
import tempfile
import time
import urllib.request
from collections.abc import Callable
from pathlib import Path

import numpy as np

CHROMIUM_NAMES = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable")


def find_chromium() -> str | None:
    """The Chromium executable (``$CHROMIUM`` first), or None."""
    env = os.environ.get("CHROMIUM")
    if env:
        return env if Path(env).is_file() else None
    for name in CHROMIUM_NAMES:
        path = shutil.which(name)
        if path:
            return path
    return None


class Browser:
    """A headless Chromium with one page, software WebGL (SwiftShader), a fixed size."""

    def __init__(self, executable: str, width: int = 960, height: int = 640) -> None:
        from websockets.sync.client import connect

        self.width, self.height = width, height
        self._profile = tempfile.TemporaryDirectory(prefix="rw-chromium-")
        self._proc = subprocess.Popen(
            [
                executable,
                "--headless",
                "--no-sandbox",  # tests may run as root, where the sandbox refuses to start
                "--use-angle=swiftshader",
                "--enable-unsafe-swiftshader",
                "--no-first-run",
                "--hide-scrollbars",
                "--mute-audio",
                f"--window-size={width},{height}",
                f"--user-data-dir={self._profile.name}",
                "--remote-debugging-port=0",
                "about:blank",
            ],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            # Its own process group: close() ends the helpers it starts (renderer, GPU,
            # crash handler) too, which otherwise write into the profile after it exits.
            start_new_session=True,
        )
        port_file = Path(self._profile.name) / "DevToolsActivePort"
        deadline = time.monotonic() + 30
        while not port_file.is_file() or not port_file.read_text().strip():
            if self._proc.poll() is not None or time.monotonic() > deadline:
                self.close()
                raise RuntimeError("chromium did not start (no DevToolsActivePort)")
            time.sleep(0.05)
        port = int(port_file.read_text().split()[0])
        with urllib.request.urlopen(f"http://127.0.0.1:{port}/json/list", timeout=10) as r:
            pages = [t for t in json.load(r) if t.get("type") == "page"]
        self._ws = connect(pages[0]["webSocketDebuggerUrl"], max_size=None)
        self._ids = itertools.count(1)
        self.events: list[str] = []
        # The window size includes the (invisible) browser frame: fix the page's size.
        self.call(
            "Emulation.setDeviceMetricsOverride",
            width=width,
            height=height,
            deviceScaleFactor=1,
            mobile=False,
        )

    def call(self, method: str, **params: object) -> dict:
        """One DevTools command; returns its result (events are kept in ``events``)."""
        msg_id = next(self._ids)
        self._ws.send(json.dumps({"id": msg_id, "method": method, "params": params}))
        while True:
            reply = json.loads(self._ws.recv(timeout=60))
            if reply.get("id") == msg_id:
                if "error" in reply:
                    raise RuntimeError(f"{method}: {reply['error']}")
                return reply.get("result", {})
            if "method" in reply:
                self.events.append(reply["method"])

    def goto(self, url: str, timeout: float = 60.0) -> None:
        """Open ``url`` and wait for its load event."""
        self.events = []
        self.call("Page.enable")
        self.call("Page.navigate", url=url)
        deadline = time.monotonic() + timeout
        while "Page.loadEventFired" not in self.events:
            if time.monotonic() > deadline:
                raise TimeoutError(f"{url} did not load within {timeout} s")
            reply = json.loads(self._ws.recv(timeout=timeout))
            if "method" in reply:
                self.events.append(reply["method"])

    def screenshot(self) -> np.ndarray:
        """The page as an ``(H, W, 3)`` uint8 RGB array."""
        from PIL import Image

        data = self.call("Page.captureScreenshot", format="png")["data"]
        image = Image.open(io.BytesIO(base64.b64decode(data))).convert("RGB")
        return np.asarray(image)

    def steady_screenshot(
        self,
        until: Callable[[np.ndarray], bool] | None = None,
        timeout: float = 90.0,
        interval: float = 0.3,
    ) -> np.ndarray:
        """A screenshot once ``until(shot)`` holds and two shots in a row are identical
        (the page has settled)."""
        deadline = time.monotonic() + timeout
        last = self.screenshot()
        while time.monotonic() < deadline:
            time.sleep(interval)
            shot = self.screenshot()
            if np.array_equal(shot, last) and (until is None or until(shot)):
                return shot
            last = shot
        raise TimeoutError(f"the page did not settle within {timeout} s")

    def close(self) -> None:
        ws = getattr(self, "_ws", None)
        if ws is not None:
            ws.close()
        self._signal_group(signal.SIGTERM)
        try:
            self._proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self._signal_group(signal.SIGKILL)
            self._proc.wait()
        self._signal_group(signal.SIGKILL)  # helpers that outlived the browser
        # A helper killed just now may have written one last file: try a few times.
        for attempt in range(5):
            try:
                self._profile.cleanup()
                break
            except OSError:
                if attempt == 4:
                    raise
                time.sleep(0.2)

    def _signal_group(self, sig: signal.Signals) -> None:
        with contextlib.suppress(ProcessLookupError):  # the group has no process left
            os.killpg(self._proc.pid, sig)

    def __enter__(self) -> Browser:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
