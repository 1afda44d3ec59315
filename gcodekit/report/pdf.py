"""Report stage: print an HTML page to PDF with headless Chromium.

Chromium lays out the same page a browser shows (the templates carry their
own ``@page`` rules), so the PDF needs no second layout engine.  Each call
gets its own throw-away profile directory so parallel workers never share one.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import tempfile
from pathlib import Path

#: Executable names of Chromium on Debian, other Linux distributions and macOS installs.
CHROMIUM_NAMES = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable")
#: Seconds a page may take to print; a report page prints in one or two.
TIMEOUT_S = 120


class ChromiumNotFound(RuntimeError):
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


def html_to_pdf(html: str | os.PathLike, pdf: str | os.PathLike) -> Path:
    """Print the page ``html`` to the file ``pdf`` (A4, no browser header or footer).

    Raises
    ------
    ChromiumNotFound, RuntimeError
        When Chromium is missing, fails or writes nothing.
    """
    html, pdf = Path(html).resolve(), Path(pdf).resolve()
    pdf.unlink(missing_ok=True)
    with tempfile.TemporaryDirectory(prefix="gcodekit-chromium-") as profile:
        cmd = chromium_command("--no-pdf-header-footer", f"--print-to-pdf={pdf}", html.as_uri(), profile=profile)
        done = subprocess.run(cmd, capture_output=True, text=True, timeout=TIMEOUT_S)
    if done.returncode != 0 or not pdf.exists() or pdf.stat().st_size == 0:
        tail = "\n".join(done.stderr.strip().splitlines()[-3:])
        raise RuntimeError(f"chromium could not print {html.name} to PDF (exit {done.returncode}): {tail}")
    return pdf
