"""Report stage: print an HTML page to PDF with headless Chromium.

Chromium lays out the same page a browser shows (the templates carry their
own ``@page`` rules), so the PDF needs no second layout engine.  Each process
keeps one headless browser and drives it over its DevTools pipe
(``--remote-debugging-pipe``: JSON messages separated by NUL bytes on file
descriptors 3 and 4): starting Chromium costs about 1.5 CPU-seconds, printing
a page in a running one about 0.3, which makes PDFs of a batch four times
cheaper than one ``--print-to-pdf`` command per page.
"""

from __future__ import annotations

import atexit
import base64
import contextlib
import fcntl
import json
import os
import select
import shutil
import subprocess
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

from ..errors import MissingDependencyError

#: Executable names of Chromium on Debian, other Linux distributions and macOS installs.
CHROMIUM_NAMES = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable")
#: Seconds Chromium may take to answer one request; a report page prints in about one.
TIMEOUT_S = 120
#: The longest path Chromium makes in its temporary folder: its single-instance socket.
SOCKET_IN_TMPDIR = "org.chromium.Chromium.XXXXXX/SingletonSocket"


class ChromiumNotFound(MissingDependencyError):
    """No Chromium to print PDFs with."""


def find_chromium() -> str:
    """Path of the Chromium executable (``$GCODEKIT_CHROMIUM`` first).

    Raises
    ------
    ChromiumNotFound
        Naming the Debian package to install.
    """
    override = os.environ.get("GCODEKIT_CHROMIUM")
    for name in ([override] if override else []) + list(CHROMIUM_NAMES):
        found = shutil.which(name)
        if found:
            return found
    raise ChromiumNotFound("PDF reports need Chromium: install it (apt-get install chromium) or pass --no-pdf")


def chromium_command(*args: str, profile: str) -> list[str]:
    """A headless Chromium command line.

    No sandbox, because reports often run as root in containers, whose small
    ``/dev/shm`` Chromium is also told not to rely on.
    """
    return [find_chromium(), "--headless", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage", "--no-first-run",
            "--disable-extensions", f"--user-data-dir={profile}", *args]


class Browser:
    """A headless Chromium driven over its DevTools pipe, with its own throw-away profile."""

    def __init__(self) -> None:
        # a plain directory, not a TemporaryDirectory, whose finalizer would remove it in a forked child too
        self._profile = _new_profile()
        to_chromium, self._pipe = os.pipe()
        self._receive, from_chromium = os.pipe()
        # above 9, so that putting them on 3 and 4 below cannot overwrite one with the other
        to_chromium, from_chromium = (_above_9(fd) for fd in (to_chromium, from_chromium))
        cmd = chromium_command("--remote-debugging-pipe", "about:blank", profile=self._profile)
        # bash (dash takes single-digit descriptors only) puts the pipe ends on 3 and 4, where Chromium reads
        self._proc = subprocess.Popen(["bash", "-c", f'exec "$0" "$@" 3<&{to_chromium} 4>&{from_chromium}', *cmd],
                                      pass_fds=(to_chromium, from_chromium), stdin=subprocess.DEVNULL,
                                      stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                      env={**os.environ, "TMPDIR": self._profile})
        os.close(to_chromium)
        os.close(from_chromium)
        self._buffer = b""
        self._next_id = 0
        self._events: list[dict[str, Any]] = []
        self._target: str | None = None
        self._session: str | None = None  # of the tab pages are printed in, attached by the first print
        # the tab asked for now, not awaited: Chromium opens it (and starts its renderer on a file: page, the
        # kind reports are) as soon as it has booted, while the report is still being drawn
        blank = Path(self._profile, "blank.html")
        blank.write_text("<!DOCTYPE html><title></title>", encoding="utf-8")
        self._tab_request: int | None = self._send("Target.createTarget", url=blank.as_uri())

    def _read(self) -> dict[str, Any]:
        while b"\0" not in self._buffer:
            ready, _, _ = select.select([self._receive], [], [], TIMEOUT_S)
            chunk = os.read(self._receive, 1 << 20) if ready else b""
            if not chunk:
                raise RuntimeError("chromium stopped answering" if ready else f"chromium silent for {TIMEOUT_S} s")
            self._buffer += chunk
        message, self._buffer = self._buffer.split(b"\0", 1)
        return json.loads(message)

    def call(self, method: str, session: str | None = None, **params: Any) -> dict[str, Any]:
        """Send one DevTools command and return its result; events that arrive meanwhile are kept."""
        return self._reply(self._send(method, session, **params), method)

    def _send(self, method: str, session: str | None = None, **params: Any) -> int:
        """Send one DevTools command without waiting; its id, for :meth:`_reply`."""
        self._next_id += 1
        message = {"id": self._next_id, "method": method, "params": params}
        if session:
            message["sessionId"] = session
        os.write(self._pipe, json.dumps(message).encode() + b"\0")
        return self._next_id

    def _reply(self, request: int, method: str) -> dict[str, Any]:
        """The result of the command ``request``; other messages that arrive meanwhile are kept."""
        for k, m in enumerate(self._events):
            if m.get("id") == request:
                reply = self._events.pop(k)
                break
        else:
            while (reply := self._read()).get("id") != request:
                self._events.append(reply)
        if "error" in reply:
            raise RuntimeError(f"chromium: {method}: {reply['error'].get('message')}")
        return reply["result"]

    def _wait_for_load(self, session: str, loader: str) -> None:
        """Until the document of the navigation ``loader`` has loaded: not any load event, which may be the
        blank page's the tab opened with."""
        while True:
            for k, m in enumerate(self._events):
                p = m.get("params", {})
                if (m.get("method") == "Page.lifecycleEvent" and m.get("sessionId") == session
                        and p.get("name") == "load" and p.get("loaderId") == loader):
                    del self._events[k]
                    return
            self._events.append(self._read())

    def print_pdf(self, url: str) -> bytes:
        """The PDF of the page at ``url``: page size from its CSS, backgrounds printed, no header or footer.

        Every page is printed in the same tab: a new tab per page started a
        renderer each time, a third to a half of a print's CPU.
        """
        if self._session is None:
            if self._tab_request is not None:
                request, self._tab_request = self._tab_request, None
                self._target = self._reply(request, "Target.createTarget")["targetId"]
            else:
                self._target = self.call("Target.createTarget", url="about:blank")["targetId"]
            self._session = self.call("Target.attachToTarget", targetId=self._target, flatten=True)["sessionId"]
            self.call("Page.enable", session=self._session)
            self.call("Page.setLifecycleEventsEnabled", session=self._session, enabled=True)
        try:
            navigation = self.call("Page.navigate", session=self._session, url=url)
            if navigation.get("errorText"):
                raise RuntimeError(f"chromium could not open {url}: {navigation['errorText']}")
            self._wait_for_load(self._session, navigation["loaderId"])
            data = self.call("Page.printToPDF", session=self._session, printBackground=True,
                             preferCSSPageSize=True, displayHeaderFooter=False)["data"]
        except (OSError, RuntimeError):
            self._session = None  # a fresh tab next time, not one left half-loaded
            with contextlib.suppress(OSError, RuntimeError):
                self.call("Target.closeTarget", targetId=self._target)
            raise
        finally:
            self._events.clear()
        return base64.b64decode(data)

    def close(self) -> None:
        """End Chromium and remove its profile.

        Killed, not asked to quit: the profile is thrown away, so there is
        nothing to save, and ``Browser.close`` took 0.15-0.2 s of every
        report command's end where the kill takes 0.03.  Its helper
        processes (zygote, renderer) end by themselves within moments of it;
        one may still be writing into the profile while it is removed.
        """
        for fd in (self._pipe, self._receive):
            os.close(fd)
        self._proc.kill()
        self._proc.wait()
        for _ in range(20):
            shutil.rmtree(self._profile, ignore_errors=True)
            if not os.path.exists(self._profile):
                break
            time.sleep(0.05)

    def forget(self) -> None:
        """Close this process's ends of the pipe only: in a forked child, Chromium is the parent's."""
        for fd in (self._pipe, self._receive):
            os.close(fd)


def _new_profile() -> str:
    """A new folder for Chromium's profile and its temporary files (its ``TMPDIR``), removed with it.

    Chromium listens on a socket in its temporary folder and stops at once
    when that path is longer than a socket's address takes (107 bytes):
    under a deep ``TMPDIR`` the profile goes into ``/tmp`` instead.
    """
    base = tempfile.gettempdir()
    if len(os.path.join(base, "gcodekit-chromium-12345678", SOCKET_IN_TMPDIR)) > 107 and os.access("/tmp", os.W_OK):
        base = "/tmp"
    return tempfile.mkdtemp(prefix="gcodekit-chromium-", dir=base)


def _above_9(fd: int) -> int:
    moved = fcntl.fcntl(fd, fcntl.F_DUPFD_CLOEXEC, 10)
    os.close(fd)
    return moved


_browser: Browser | None = None
_lock = threading.Lock()  # Dask workers may print from several threads of one process


def _close_browser() -> None:
    global _browser
    if _browser is not None:
        _browser.close()
        _browser = None


def _forget_browser() -> None:
    """In a forked child: the parent's browser is not the child's to use or quit."""
    global _browser, _lock
    if _browser is not None:
        _browser.forget()
        _browser = None
    _lock = threading.Lock()


atexit.register(_close_browser)
os.register_at_fork(after_in_child=_forget_browser)


def start_browser() -> None:
    """Start this process's Chromium now, without waiting for it: it boots (about 1.5 CPU-seconds)
    on another core while the first report is computed, instead of after it.

    Raises
    ------
    ChromiumNotFound
        When there is no Chromium.
    """
    global _browser
    with _lock:
        if _browser is None:
            _browser = Browser()


def html_to_pdf(html: str | os.PathLike, pdf: str | os.PathLike) -> Path:
    """Print the page ``html`` to the file ``pdf`` (A4 from the page's CSS).

    Uses this process's browser, started on first use; a browser that died
    is started again once.

    Raises
    ------
    ChromiumNotFound, RuntimeError
        When Chromium is missing or cannot print the page.
    """
    global _browser
    html, pdf = Path(html).resolve(), Path(pdf).resolve()
    with _lock:
        for attempt in (1, 2):
            if _browser is None:
                _browser = Browser()
            try:
                data = _browser.print_pdf(html.as_uri())
                break
            except (OSError, RuntimeError):
                _close_browser()
                if attempt == 2:
                    raise
    pdf.write_bytes(data)
    return pdf
