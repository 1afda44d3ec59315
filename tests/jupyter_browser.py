"""Drive a real JupyterLab in Debian's Chromium with Playwright (browser tests and benchmarks).

The server runs on a free local port with no token, its root a folder the
caller chooses; Playwright's own browser download is not used (it cannot be
fetched here): Debian's ``/usr/bin/chromium`` is launched instead, with
SwiftShader for WebGL.  Also used by ``benchmarks/bench_widgets.py``.
"""

from __future__ import annotations

import io
import json
import os
import shutil
import socket
import subprocess
import sys
import time
import urllib.request
from contextlib import contextmanager
from pathlib import Path

import numpy as np

#: WebGL through SwiftShader (no GPU here) with the page composited in software, as Chromium does by
#: itself on a machine without a GPU: compositing whole pages through SwiftShader cost 150-400 ms a
#: frame here.  GCODEKIT_CHROMIUM_ARGS adds flags (for benchmarks).
CHROMIUM_ARGS = ["--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--disable-gpu-compositing",
                 *os.environ.get("GCODEKIT_CHROMIUM_ARGS", "").split()]


def chromium_path() -> str | None:
    for name in ("chromium", "chromium-browser", "google-chrome"):
        found = shutil.which(name)
        if found:
            return found
    return None


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@contextmanager
def jupyter_lab(root: Path, timeout_s: float = 90.0):
    """A JupyterLab server serving ``root``; yields its base URL."""
    port = _free_port()
    log = open(root / "jupyter.log", "w")
    # every cell rendered (JupyterLab 4 otherwise hides the cells out of view, and their widgets)
    settings = root / ".settings" / "@jupyterlab" / "notebook-extension"
    settings.mkdir(parents=True, exist_ok=True)
    (settings / "tracker.jupyterlab-settings").write_text(json.dumps({"windowingMode": "none"}))
    announcements = root / ".settings" / "@jupyterlab" / "apputils-extension"
    announcements.mkdir(parents=True, exist_ok=True)
    (announcements / "notification.jupyterlab-settings").write_text(
        json.dumps({"fetchNews": "false", "checkForUpdates": False}))
    env = {**os.environ, "JUPYTER_CONFIG_DIR": str(root / ".jupyter"), "JUPYTER_RUNTIME_DIR": str(root / ".runtime")}
    process = subprocess.Popen(
        [sys.executable, "-m", "jupyterlab", "--no-browser", f"--port={port}", "--ip=127.0.0.1",
         "--ServerApp.token=", "--ServerApp.password=", "--LabApp.expose_app_in_browser=True", "--allow-root",
         f"--ServerApp.root_dir={root}", f"--LabApp.user_settings_dir={root / '.settings'}",
         f"--LabApp.workspaces_dir={root / '.workspaces'}", "--LabApp.news_url=",
         "--LabApp.check_for_updates_class=jupyterlab.NeverCheckForUpdate"],
        stdout=log, stderr=subprocess.STDOUT, env=env, cwd=root)
    url = f"http://127.0.0.1:{port}"
    try:
        deadline = time.monotonic() + timeout_s
        while True:
            try:
                with urllib.request.urlopen(f"{url}/api/status", timeout=2):
                    break
            except OSError:
                if process.poll() is not None or time.monotonic() > deadline:
                    raise RuntimeError(f"JupyterLab did not start: {(root / 'jupyter.log').read_text()[-2000:]}")
                time.sleep(0.3)
        yield url
    finally:
        process.terminate()
        try:
            process.wait(15)
        except subprocess.TimeoutExpired:
            process.kill()
        log.close()


@contextmanager
def browser_page(width: int = 1400, height: int = 1000):
    """A Playwright page in Debian's Chromium; ``page.console_errors`` collects the console's errors."""
    from playwright.sync_api import sync_playwright

    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=chromium_path(), args=CHROMIUM_ARGS)
        page = browser.new_page(viewport={"width": width, "height": height})
        errors: list[str] = []
        page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
        page.on("pageerror", lambda e: errors.append(str(e)))
        page.console_errors = errors
        try:
            yield page
        finally:
            browser.close()


def open_and_run(page, url: str, notebook: str, timeout_s: float = 240.0, before_run=None) -> None:
    """Open ``notebook`` in JupyterLab and run all its cells, waiting until none is busy.

    ``before_run(page)``, when given, is called once the kernel is idle, just before the cells run.
    """
    page.goto(f"{url}/lab/tree/{notebook}?reset")
    page.wait_for_function("window.jupyterapp && document.querySelector('.jp-NotebookPanel .jp-Cell')",
                           timeout=timeout_s * 1000)
    # the kernel must be idle before running (it starts with the panel)
    page.wait_for_function("document.querySelector('.jp-NotebookPanel') && "
                           "window.jupyterapp.shell.currentWidget?.sessionContext?.session?.kernel?.status === 'idle'",
                           timeout=timeout_s * 1000)
    if before_run is not None:
        before_run(page)
    page.evaluate("window.jupyterapp.commands.execute('notebook:run-all-cells')")
    page.wait_for_timeout(500)
    page.wait_for_function(
        "[...document.querySelectorAll('.jp-InputPrompt')].every(p => !p.textContent.includes('*')) && "
        "window.jupyterapp.shell.currentWidget.sessionContext.session.kernel.status === 'idle'",
        timeout=timeout_s * 1000, polling=250)


def delete_sessions(url: str) -> None:
    """End the server's kernel sessions (a reopened notebook would keep its old kernel)."""
    with urllib.request.urlopen(f"{url}/api/sessions") as r:
        sessions = json.load(r)
    for s in sessions:
        request = urllib.request.Request(f"{url}/api/sessions/{s['id']}", method="DELETE")
        urllib.request.urlopen(request).close()


def shot(locator):
    """A screenshot of ``locator`` as an (height, width, 3) int array."""
    from PIL import Image

    return np.asarray(Image.open(io.BytesIO(locator.screenshot())).convert("RGB"), dtype=int)


def trame_view(page, name: str):
    """The output area and picture frame of a trame view (``gcodekit-<name>-view``), once its canvas exists."""
    area = page.locator(f".jp-OutputArea-child:has(.gcodekit-{name}-view)")
    frame = area.locator(f"iframe.gcodekit-{name}-frame")
    frame.wait_for(timeout=60_000)
    page.frame_locator(f"iframe.gcodekit-{name}-frame").locator("canvas").first.wait_for(timeout=60_000)
    return area, frame


def shot_when(frame, ready, timeout_s=60.0):
    """Screenshots of the view until ``ready(picture)`` holds or the time is up; the last one (the caller asserts)."""
    deadline = time.monotonic() + timeout_s
    while True:
        picture = shot(frame)
        if ready(picture) or time.monotonic() > deadline:
            return picture
        time.sleep(0.5)


def wait_for_picture(frame, previous, timeout_s=120.0):
    """Poll the view until its picture differs from ``previous``; the new picture and the seconds waited."""
    start = time.perf_counter()
    while time.perf_counter() - start < timeout_s:
        now = shot(frame)
        if np.mean(np.any(now != previous, axis=2)) > 0.002:
            waited = time.perf_counter() - start
            time.sleep(0.5)  # then let it settle
            return shot(frame), waited
        time.sleep(0.05)
    raise AssertionError("the view's picture did not change")


def settled(frame, timeout_s=30.0):
    """The view's picture once two screenshots half a second apart agree (it has finished drawing)."""
    before = shot(frame)
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        time.sleep(0.5)
        now = shot(frame)
        if np.array_equal(now, before):
            return now
        before = now
    return before


def drag_turns(page, frame, before, attempts=3):
    """Drag across the view's middle until its picture changes (a view still loading may miss the first drag)."""
    box = frame.bounding_box()
    cx, cy = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
    for attempt in range(attempts):
        page.mouse.move(cx, cy)
        page.mouse.down()
        page.mouse.move(cx + 160, cy + 40, steps=12)
        page.mouse.up()
        try:
            return wait_for_picture(frame, before, timeout_s=90)[0]
        except AssertionError:
            if attempt == attempts - 1:
                raise
    raise AssertionError("unreachable")
