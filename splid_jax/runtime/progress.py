"""One terminal line per chunk (per sweep chunk: one summary line), from the metrics.jsonl record; on a
CPU, lines from inside a chunk too (``Watch``)."""

from __future__ import annotations

import contextlib
import json
import os
import sys
import threading
import time
from collections.abc import Callable, Iterator

from splid_jax.common.ticks import EXPLORED, ITERATION

# A program with the chunk's ticks (``common.ticks``) is one JAX keeps out of its compile cache.
NOT_CACHED = "not kept in the compile cache while the display shows progress inside a chunk: --quiet keeps it"


def _si(x: float) -> str:
    for unit, scale in (("G", 1e9), ("M", 1e6), ("k", 1e3)):
        if abs(x) >= scale:
            return f"{x / scale:.1f}{unit}"
    return f"{x:.0f}"


def _extra(rec: dict) -> list[tuple[str, str]]:
    """(title, text) of the columns an algorithm's own keys give: its buffer, SELECT's acceptance, losses."""
    cols = []
    if "buffer_size" in rec:
        cols.append(("buffer", _si(rec["buffer_size"])))
    if "select_pairs" in rec and "select_accepted" in rec:
        cols.append(("accept", f"{rec['select_accepted'] / max(rec['select_pairs'], 1):.1%}"))
    for k in rec:
        if k.endswith("_loss"):
            cols.append((k.replace("_", " "), f"{rec[k]:.4f}"))
    return cols


def header(rec: dict) -> str:
    extra = "".join(f" {title:>9}" for title, _ in _extra(rec))
    return (
        f"{'iter':>9} {'episodes':>9} {'env st':>7} {'select st':>9} {'steps/s':>8} {'success':>7} {'final':>6} "
        f"{'return':>7}{extra} {'wall s':>7}"
    )


def line(rec: dict, total_iterations: int) -> str:
    extra = "".join(f" {text:>9}" for _, text in _extra(rec))
    return (
        f"{rec['iteration']:>4}/{total_iterations:<4} {rec['episodes']:>9,} {_si(rec['env_steps']):>7} "
        f"{_si(rec['select_steps']):>9} {_si(rec['steps_per_s']):>8} {rec['eval_success']:>7.3f} "
        f"{rec['eval_success_final']:>6.3f} {rec['eval_return']:>7.2f}{extra} {rec['wall_s']:>7.1f}"
    )


def sweep_line(recs: list[dict], total_iterations: int) -> str:
    """The members' mean and best success after a chunk of a sweep."""
    mean = sum(r["eval_success"] for r in recs) / len(recs)
    best = max(r["eval_success"] for r in recs)
    final = sum(r["eval_success_final"] for r in recs) / len(recs)
    return (
        f"iter {recs[0]['iteration']:>5}/{total_iterations}  mean success {mean:.3f} (final step {final:.3f})  "
        f"best {best:.3f}  steps/s per member {_si(recs[0]['steps_per_s'])}  wall {recs[0]['wall_s']:.1f}s"
    )


def show(text: str, quiet: bool = False) -> None:
    """``text`` on stdout; once stdout is closed (``| head``) the display goes quiet and the work goes on."""
    if quiet:
        return
    try:
        print(text, file=sys.stdout, flush=True)
    except BrokenPipeError:
        quiet_stdout()


def quiet_stdout() -> None:
    """stdout's descriptor pointed at /dev/null: what is still buffered, and any later print, goes
    nowhere instead of raising again (at exit too)."""
    with contextlib.suppress(OSError, ValueError):
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)


class Watch:
    """What the chunk under way has done (``common.ticks``' watcher), shown as one line at most every
    ``interval`` seconds, from a timer of its own where no tick comes (0: a line at every tick, no timer).
    Ticks arrive on XLA's thread; those of a chunk no longer waited for (a signal) are not shown."""

    def __init__(self, show: Callable[[str], None], iterations: int, counters: Callable[[int, int], dict],
                 interval: float = 10.0, clock: Callable[[], float] = time.monotonic):  # fmt: skip
        """``iterations``: a chunk's; ``counters``: the learner's (``learners.base.Algorithm.counters``)."""
        self.show, self.iterations, self.counters = show, iterations, counters
        self.interval, self.clock = interval, clock
        self.lock = threading.RLock()
        self.running = False
        self.begin(0)

    def begin(self, iteration: int) -> None:
        """A chunk starts after ``iteration`` completed iterations."""
        with self.lock:
            self.first, self.done, self.explored, self.rounds, self.left = iteration, iteration, False, 0, None
            self.started = self.shown = self.clock()

    def seen(self, stage: str, value) -> None:
        with self.lock:
            if stage == ITERATION:
                self.done, self.explored, self.rounds, self.left = int(value), False, 0, None
            elif stage == EXPLORED:
                self.done, self.explored, self.rounds, self.left = int(value), True, 0, None
            else:
                self.rounds, self.left = self.rounds + 1, int(value)
            self.show_if_due()

    def line(self) -> str:
        with self.lock:
            n = self.done - self.first + 1  # the iteration under way, counted in the chunk
            if n > self.iterations:
                doing = f"{self.iterations} iterations trained, evaluating"
            elif not self.explored:
                doing = f"iteration {n}/{self.iterations} of the chunk: started"
            else:
                doing = f"iteration {n}/{self.iterations} of the chunk: explored"
                if self.left is not None:
                    doing += f", SELECT round {self.rounds} ({self.left:,} verdicts left)"
            episodes = self.counters(self.done + self.explored, 0)["episodes"]
            return f"  ... {doing}; {episodes:,} episodes explored, {self.clock() - self.started:.0f} s into the chunk"

    def show_if_due(self) -> None:
        with self.lock:  # one line at a time, from either thread
            now = self.clock()
            if self.running and now - self.shown >= self.interval:
                self.shown = now
                self.show(self.line())

    @contextlib.contextmanager
    def chunk(self, iteration: int) -> Iterator[None]:
        """While the chunk from ``iteration`` is waited for."""
        self.begin(iteration)
        stop = threading.Event()

        def timer():  # wakes when the next line is due, however the last one came
            while not stop.wait(max(0.0, self.shown + self.interval - self.clock())):
                self.show_if_due()

        thread = threading.Thread(target=timer, name="splid_jax-progress", daemon=True)
        self.running = True
        if self.interval > 0:
            thread.start()
        try:
            yield
        finally:
            with self.lock:
                self.running = False
            stop.set()
            if thread.is_alive():
                thread.join()


def read_metrics(path: str, error: type[Exception]) -> list[dict]:
    """The records of a metrics.jsonl; a torn last line (the writer was killed mid-line) is dropped,
    any other bad line, or bytes that are not UTF-8, raises ``error`` naming the file and line."""
    if not os.path.exists(path):
        return []
    with open(path, "rb") as fh:
        data = fh.read()
    lines = data.split(b"\n")
    if lines and lines[-1] == b"":
        lines.pop()
    records = []
    for n, raw in enumerate(lines, 1):
        torn = n == len(lines) and not data.endswith(b"\n")
        try:
            record = json.loads(raw.decode())
        except (UnicodeDecodeError, json.JSONDecodeError) as e:
            if not raw.strip():
                continue
            if torn:
                break
            why = "not UTF-8 text" if isinstance(e, UnicodeDecodeError) else f"not a JSON record ({e.msg})"
            raise error(f"{path}:{n}: {why}") from None
        if not isinstance(record, dict) or not isinstance(record.get("iteration", 0), int):
            if torn:
                break
            raise error(f"{path}:{n}: not a metrics record (a JSON object with an integer iteration)")
        records.append(record)
    return records
