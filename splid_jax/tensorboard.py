"""TensorBoard event files for the metrics the loop records, beside ``metrics.jsonl``.

``MetricsWriter(DIR).write(record)`` takes one record as the loop writes it to ``metrics.jsonl`` and
writes each of its numeric scalars against ``record["episodes"]`` (the x-axis every figure of the
project uses, comparable across algorithms and batch sizes). ``convert`` does the same for a whole
existing ``metrics.jsonl``: ``python -m splid_jax.tensorboard RUN_DIR/metrics.jsonl OUT_DIR``.
Needs the optional extra: ``pip install -e ".[tensorboard]"`` (tensorboardX).
"""

from __future__ import annotations

from splid_jax.cli import Parser, check_environment, exit_with, quiet_interrupts, run_main

if __name__ == "__main__":  # a signal while it loads or works ends the process with one line, no traceback
    quiet_interrupts("")
    check_environment()

import contextlib  # noqa: E402
import math  # noqa: E402
import os  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from collections.abc import Callable, Iterator  # noqa: E402

from splid_jax.common.errors import InvalidConfig  # noqa: E402
from splid_jax.common.paths import unwritable  # noqa: E402

STEP_KEY = "episodes"
EXTRA = 'pip install -e ".[tensorboard]"'


class TensorBoardUnavailable(RuntimeError):
    """tensorboardX is not installed."""


def scalars(record: dict) -> dict[str, float]:
    """The record's finite numeric scalars (booleans and the step itself left out)."""
    out = {}
    for key, value in record.items():
        if key == STEP_KEY or isinstance(value, bool) or not isinstance(value, int | float):
            continue
        if math.isfinite(value):
            out[key] = float(value)
    return out


class MetricsWriter:
    """Writes metrics records as TensorBoard scalars under ``log_dir``; a context manager. Each record
    is written and flushed before ``write`` returns, so a full disk is an error of the caller's, not a
    traceback in a writer thread and a silently missing file."""

    def __init__(self, log_dir: str):
        try:
            from tensorboardX.event_file_writer import EventsWriter
            from tensorboardX.proto.event_pb2 import Event
            from tensorboardX.summary import scalar
        except ImportError:
            raise TensorBoardUnavailable(f"tensorboardX is not installed: {EXTRA}") from None
        self._event, self._scalar = Event, scalar
        os.makedirs(log_dir, exist_ok=True)
        self._writer = EventsWriter(os.path.join(log_dir, "events"))  # events.out.tfevents.TIME.HOST

    def write(self, record: dict, flush: bool = True) -> None:
        step, now = int(record[STEP_KEY]), time.time()
        for key, value in scalars(record).items():
            self._writer.write_event(self._event(summary=self._scalar(key, value), step=step, wall_time=now))
        if flush:
            self._writer.flush()

    def flush(self) -> None:
        self._writer.flush()

    def close(self) -> None:
        self._writer.close()

    def __enter__(self) -> MetricsWriter:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


@contextlib.contextmanager
def recording(log_dir: str | None, per_member: bool = False) -> Iterator[Callable[[str, dict], None] | None]:
    """The host loop's ``on_record`` callback writing every record under ``log_dir`` (a sweep's members
    each in the subdirectory of its run directory's name), or None without a directory. A missing
    extra is a mistake in the command line, found before any work."""
    if not log_dir:
        yield None
        return
    try:
        import tensorboardX  # noqa: F401
    except ImportError:
        raise InvalidConfig("tensorboard", log_dir, f"given with tensorboardX installed ({EXTRA})") from None
    why = unwritable(log_dir)
    if why:
        raise InvalidConfig("tensorboard", log_dir, f"a writable directory ({why})")
    writers: dict[str, MetricsWriter] = {}

    def on_record(run_dir: str, record: dict) -> None:
        name = os.path.basename(os.path.normpath(run_dir)) if per_member else ""
        if name not in writers:
            writers[name] = MetricsWriter(os.path.join(log_dir, name))
        writers[name].write(record)

    try:
        yield on_record
    finally:  # every record is flushed as written: a close failing on a full disk loses nothing
        for writer in writers.values():
            with contextlib.suppress(OSError):
                writer.close()


class BadMetrics(ValueError):
    """A metrics file with a line that is no metrics record."""


def convert(metrics_path: str, log_dir: str) -> int:
    """Write every record of ``metrics_path`` (a ``metrics.jsonl``) as event files under ``log_dir``;
    returns the number of records written (records without ``episodes`` are skipped; a torn last line,
    as a killed writer leaves it, is dropped)."""
    from splid_jax.runtime.progress import read_metrics

    if os.path.isdir(metrics_path):
        raise BadMetrics(f"{metrics_path}: a directory, not a metrics.jsonl")
    if not os.path.exists(metrics_path):
        raise BadMetrics(f"{metrics_path}: no such file")
    records = [r for r in read_metrics(metrics_path, BadMetrics) if STEP_KEY in r]
    bad = next((n for n, r in enumerate(records, 1) if not isinstance(r[STEP_KEY], int | float)), None)
    if bad is not None:
        raise BadMetrics(f"{metrics_path}: record {bad} has a non-numeric {STEP_KEY}")
    why = unwritable(log_dir)
    if why:
        raise BadMetrics(f"{log_dir}: not a writable directory ({why})")
    with MetricsWriter(log_dir) as writer:
        for record in records:
            writer.write(record, flush=False)
    return len(records)


def main(argv: list[str] | None = None) -> int:
    p = Parser(prog="python -m splid_jax.tensorboard", description=__doc__.splitlines()[0])
    p.add_argument("metrics", metavar="METRICS.jsonl")
    p.add_argument("log_dir", metavar="OUT_DIR")
    a = p.parse_args(argv)
    try:
        n = convert(a.metrics, a.log_dir)
    except (OSError, TensorBoardUnavailable, BadMetrics) as err:
        print(f"{p.prog}: error: {err}", file=sys.stderr)
        return 2
    print(f"{n} records of {a.metrics} written to {a.log_dir}")
    return 0


if __name__ == "__main__":
    exit_with(run_main(main))
