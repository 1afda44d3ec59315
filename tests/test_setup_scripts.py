"""The set-up scripts: apt-get waits for the package lock, within a bound, and says who holds it."""

from __future__ import annotations

import fcntl
import os
import subprocess
import sys
import threading
from pathlib import Path

SCRIPTS = Path(__file__).parents[1] / "scripts"


def _wait_for_lock(lock: Path, wait_s: int) -> subprocess.CompletedProcess:
    script = f'set -euo pipefail; PY={sys.executable}; die() {{ echo "gcodekit setup: $*" >&2; exit 1; }}; ' \
             f'source {SCRIPTS / "apt.sh"}; wait_for_apt_lock'
    env = {**os.environ, "GCODEKIT_APT_LOCKS": str(lock), "APT_LOCK_WAIT": str(wait_s), "APT_LOCK_POLL": "1"}
    return subprocess.run(["bash", "-c", script], env=env, capture_output=True, text=True, timeout=60)


def test_a_free_lock_goes_straight_on(tmp_path):
    done = _wait_for_lock(tmp_path / "lock-frontend", 1)
    assert done.returncode == 0 and done.stderr == ""


def test_a_held_lock_is_waited_for_then_given_up_with_the_holder_named(tmp_path):
    lock = tmp_path / "lock-frontend"
    with open(lock, "a") as handle:
        fcntl.lockf(handle, fcntl.LOCK_EX)
        done = _wait_for_lock(lock, 2)
    assert done.returncode == 1
    assert "waiting for the package lock" in done.stderr
    assert "still held after 2 s" in done.stderr
    assert f"pid {os.getpid()}" in done.stderr  # the holder is named


def test_a_lock_released_while_waiting_lets_the_install_go_on(tmp_path):
    lock = tmp_path / "lock-frontend"
    handle = open(lock, "a")
    fcntl.lockf(handle, fcntl.LOCK_EX)
    threading.Timer(1.5, handle.close).start()  # closing the file releases the lock
    done = _wait_for_lock(lock, 30)
    assert done.returncode == 0, done.stderr
    assert "the package lock is free after" in done.stderr
