"""Read stage, ahead of the consumer: a large program's chunks read on a second thread.

Decompressing (zlib) and scanning (the compiled scanner) release the GIL,
so on a machine with a second core the next chunk can be read while the
parser and the machine work on this one: on a 3 M-line print this takes
about half a second off the run.  The result is the serial one: the
producer reports its problems to a :class:`_Recorder`, and each chunk's
reports are replayed into the real diagnostics just before the chunk is
handed over, where the serial reader would have made them.  In strict mode
the replay raises where the serial reader would have raised; the producer
has read on by then, which costs time but changes nothing.

The producer is stopped and its source closed when the consumer stops
early (an error, ``close()``, a broken-off loop).
"""

from __future__ import annotations

import queue
import threading
from typing import Any, Callable, Iterator, TypeVar

from ..errors import Diagnostics

__all__ = ["read_ahead"]

T = TypeVar("T")
_END = object()
_POLL_S = 0.1  # how often a producer waiting on a full queue checks whether it was stopped


class _Recorder:
    """Stands in for :class:`Diagnostics` on the producer's thread: keeps the reports, in order."""

    def __init__(self, file: str):
        self.file = file
        self.calls: list[tuple[tuple, dict[str, Any]]] = []

    def report(self, *args, **kwargs) -> None:
        self.calls.append((args, kwargs))

    def warn(self, line: int, column: int, message: str, text: str = "") -> None:
        self.report(line, column, message, text, severity="warning")

    def take(self) -> list[tuple[tuple, dict[str, Any]]]:
        calls, self.calls = self.calls, []
        return calls


def read_ahead(produce: Callable[[Diagnostics], Iterator[T]], diagnostics: Diagnostics,
               depth: int = 1) -> Iterator[T]:
    """The items of ``produce(diagnostics)``, made on another thread up to ``depth`` items ahead.

    ``produce`` must report problems only through the diagnostics it is
    given (``report``, ``warn`` and ``file`` are what it may use).
    """
    recorder = _Recorder(diagnostics.file)
    handover: queue.Queue = queue.Queue(maxsize=depth)
    stop = threading.Event()

    def put(item) -> bool:
        while not stop.is_set():
            try:
                handover.put(item, timeout=_POLL_S)
                return True
            except queue.Full:
                continue
        return False

    def work() -> None:
        items = None
        try:
            items = produce(recorder)  # type: ignore[arg-type]
            for item in items:
                if not put((item, recorder.take())):
                    return
            put((_END, recorder.take()))
        except BaseException as exc:  # handed over and raised on the consumer's thread
            put((exc, recorder.take()))
        finally:
            close = getattr(items, "close", None)
            if close is not None:
                close()

    producer = threading.Thread(target=work, name="gcodekit-read-ahead", daemon=True)
    producer.start()
    try:
        while True:
            item, calls = handover.get()
            for args, kwargs in calls:
                diagnostics.report(*args, **kwargs)
            if item is _END:
                return
            if isinstance(item, BaseException):
                raise item
            yield item
    finally:
        stop.set()
        producer.join()
