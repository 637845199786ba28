"""SIGINT (Ctrl-C) and SIGTERM (what a preemptible cluster sends) stop a run alike at any moment,
compilation included: the host loop checkpoints the newest state that is whole and raises
``Interrupted``, which the command lines turn into exit code 130 (SIGINT) or 143 (SIGTERM)."""

from __future__ import annotations

import signal
import threading
import time
from collections.abc import Callable
from typing import Any

import jax

from splid_jax.runtime import multihost


class Interrupted(KeyboardInterrupt):
    """SIGINT or SIGTERM stopped the run; ``exit_code`` is 128 + the signal's number."""

    def __init__(self, signum: int):
        super().__init__(signal.Signals(signum).name)
        self.signum = signum
        self.exit_code = 128 + signum


class SaveAbandoned(Interrupted):
    """A signal came while a checkpoint was written, and the write was not waited for: the last
    whole checkpoint is the one kept (orbax renames a step into place only once it is complete)."""


# Seconds a save may go on after a signal: a state of gigabytes is written in that time, and a
# save stuck on a full or hung filesystem does not hold the process any longer.
GRACE_S = 10.0


class Signals:
    """SIGINT and SIGTERM only set a flag, read between steps. Blocking work (tracing, compiling, a
    chunk) runs in a daemon thread while the main thread waits in short slices, so a signal is seen
    within a fraction of a second instead of after a compilation of minutes.

    Over several processes a signal is acted on only after a chunk, where every process learns of it
    (``agree``): all then stop at the same iteration and take part in its checkpoint."""

    def __init__(self):
        self.signum: int | None = None
        self.count = 0  # signals caught: a second one ends a checkpoint save at once
        self.shared = jax.process_count() > 1
        self._previous: dict[int, Any] = {}

    def __enter__(self) -> Signals:
        if threading.current_thread() is threading.main_thread():
            for sig in (signal.SIGINT, signal.SIGTERM):
                self._previous[sig] = signal.signal(sig, self._caught)
        return self

    def __exit__(self, *exc) -> None:
        for sig, handler in self._previous.items():
            signal.signal(sig, handler)

    def _caught(self, signum, frame) -> None:
        self.count += 1
        if self.signum is None:
            self.signum = signum

    def check(self) -> None:
        if self.signum is not None and not self.shared:
            raise Interrupted(self.signum)

    def agree(self) -> None:
        """``check``, after every process has told the others of the signal it got, if any."""
        if self.shared:
            self.signum = multihost.any_of(self.signum or 0) or None
            if self.signum is not None:
                raise Interrupted(self.signum)
        self.check()

    def wait(
        self, fn: Callable[[], Any], late_after: float | None = None, on_late: Callable[[float], None] | None = None
    ) -> Any:
        """``fn()`` in a daemon thread; raises ``Interrupted`` as soon as a signal came (the thread is
        left to finish or to die with the process). Once ``fn`` has run ``late_after`` seconds,
        ``on_late(seconds)`` is called, once: a program stuck on its device says so instead of
        leaving a silent process."""
        self.check()
        start = time.monotonic()
        thread, box = _started(fn)
        while thread.is_alive():
            thread.join(0.05)
            self.check()
            if late_after is not None and on_late is not None and time.monotonic() - start > late_after:
                on_late(time.monotonic() - start)
                late_after = None
        return _result(box)

    def begin(self, fn: Callable[[], Any]) -> Callable[[], Any]:
        """``fn()`` started now in a daemon thread, beside whatever the caller waits on next; the returned
        function, given to ``wait``, collects its result (or raises its error)."""
        thread, box = _started(fn)

        def joined() -> Any:
            thread.join()
            return _result(box)

        return joined

    def finish(self, fn: Callable[[], Any], grace: float = GRACE_S) -> Any:
        """``fn()`` (a checkpoint save) in a daemon thread, which a first signal does not cut short: a
        signal before or during it leaves it ``grace`` seconds, a further signal none. Past that it
        raises ``SaveAbandoned``, whatever ``fn`` waits on. Over several processes it is ``fn()``,
        which every process must reach."""
        if self.shared:
            return fn()
        seen = self.count
        deadline = time.monotonic() + grace if self.signum is not None else None
        thread, box = _started(fn)
        while thread.is_alive():
            thread.join(0.05)
            new, seen = self.count - seen, self.count
            if new and deadline is None:
                deadline = time.monotonic() + grace
                new -= 1
            if new or (deadline is not None and time.monotonic() > deadline):
                raise SaveAbandoned(self.signum or signal.SIGINT)
        return _result(box)


def _started(fn: Callable[[], Any]) -> tuple[threading.Thread, dict[str, Any]]:
    box: dict[str, Any] = {}

    def work():
        try:
            box["out"] = fn()
        except BaseException as e:  # handed to the main thread as is
            box["err"] = e

    thread = threading.Thread(target=work, name="splid_jax-work", daemon=True)
    thread.start()
    return thread, box


def _result(box: dict[str, Any]) -> Any:
    if "err" in box:
        raise box["err"]
    return box["out"]
