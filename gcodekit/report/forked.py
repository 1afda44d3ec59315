"""Report stage: one piece of a report's work done in a forked child while this process does the rest.

A report spends about half its CPU time drawing and encoding pictures, and a
command-line report otherwise runs on one core.  Forked after the imports and
the emulation, a child starts with the operation and matplotlib already in
memory (nothing to send it but the pictures' ``data:`` URIs back), and draws
some of the pictures while this process computes the numbers and draws the
others: the cylinder's HTML report went from 4.0 to about 3 s on two cores.

Forking is only safe in a process that runs no other thread (another thread
may hold a lock the child then waits on forever) and only exists on POSIX;
macOS libraries do not survive a fork.  Elsewhere the work runs in this
process instead, with the same result.
"""

from __future__ import annotations

import atexit
import os
import pickle
import signal
import sys
import threading
import traceback
from typing import Callable, Generic, TypeVar

T = TypeVar("T")

#: The children forked and not yet waited for: ended with the process (a report stopped by a signal must not
#: leave its child drawing, holding the command's output open)
_running: set[int] = set()


def can_fork() -> bool:
    """True on Linux in a process running one thread: where a forked child cannot inherit a held lock."""
    return sys.platform.startswith("linux") and hasattr(os, "fork") and threading.active_count() == 1


class Forked(Generic[T]):
    """``work()`` run in a forked child from now on; :meth:`result` waits for it.

    Where :func:`can_fork` is false, ``work()`` runs here, now.  An exception
    in the child is raised again by :meth:`result` (as a ``RuntimeError``
    carrying the child's traceback when it cannot be pickled).

    Examples
    --------
    >>> Forked(lambda: 6 * 7).result()
    42
    """

    def __init__(self, work: Callable[[], T]) -> None:
        self._pid = 0
        self._done: tuple[bool, object] | None = None
        if not can_fork():
            self._done = _outcome(work)
            return
        self._receive, send = os.pipe()
        self._pid = os.fork()
        if self._pid == 0:  # the child: work, send its outcome, leave without the parent's exit handlers
            status = 1
            try:
                os.close(self._receive)
                with os.fdopen(send, "wb") as out:
                    out.write(_pickled(_outcome(work)))
                status = 0
            finally:
                os._exit(status)
        os.close(send)
        _running.add(self._pid)

    def result(self) -> T:
        """The child's result (read before waiting for it: a large one would fill the pipe and block it)."""
        if self._done is None:
            with os.fdopen(self._receive, "rb") as stream:
                message = stream.read()
            _, status = os.waitpid(self._pid, 0)
            _running.discard(self._pid)
            if not message:
                raise RuntimeError(f"the forked process drawing the report died (wait status {status})")
            self._done = pickle.loads(message)
        ok, value = self._done
        if not ok:
            raise value  # type: ignore[misc]
        return value  # type: ignore[return-value]


def _end_children() -> None:
    """Kill and reap the children still drawing: the process ends (its exit handlers run, as after a SIGTERM
    the command turns into an exit) without waiting for their pictures."""
    while _running:
        pid = _running.pop()
        try:
            os.kill(pid, signal.SIGKILL)
            os.waitpid(pid, 0)
        except (ProcessLookupError, ChildProcessError):  # ended and reaped already
            pass


atexit.register(_end_children)


def _outcome(work: Callable[[], T]) -> tuple[bool, object]:
    try:
        return True, work()
    except Exception as exc:  # noqa: BLE001 -- handed to result(), which raises it in the parent
        return False, exc


def _pickled(outcome: tuple[bool, object]) -> bytes:
    try:
        return pickle.dumps(outcome)
    except Exception:  # noqa: BLE001 -- an exception (or result) that does not pickle: send its text
        exc = outcome[1]
        text = "".join(traceback.format_exception(exc)) if isinstance(exc, BaseException) else repr(exc)
        return pickle.dumps((False, RuntimeError(f"in the forked process: {text}")))
