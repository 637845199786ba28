"""TensorBoard event files for the metrics the loop records, beside ``metrics.jsonl``.

``MetricsWriter(DIR).write(record)`` takes one record as the loop writes it to ``metrics.jsonl`` and
writes each of its numeric scalars against ``record["episodes"]`` (the x-axis every figure of the
project uses, comparable across algorithms and batch sizes). ``convert`` does the same for a whole
existing ``metrics.jsonl``: ``python -m splid_jax.tensorboard RUN_DIR/metrics.jsonl OUT_DIR``.
Needs the optional extra: ``pip install -e ".[tensorboard]"`` (tensorboardX).
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import os
import sys
from collections.abc import Callable, Iterator

from splid_jax.common.errors import InvalidConfig

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
    """Writes metrics records as TensorBoard scalars under ``log_dir``; a context manager."""

    def __init__(self, log_dir: str):
        try:
            from tensorboardX import SummaryWriter
        except ImportError:
            raise TensorBoardUnavailable(f"tensorboardX is not installed: {EXTRA}") from None
        self._writer = SummaryWriter(log_dir=log_dir)

    def write(self, record: dict) -> None:
        step = int(record[STEP_KEY])
        for key, value in scalars(record).items():
            self._writer.add_scalar(key, value, global_step=step)

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
    writers: dict[str, MetricsWriter] = {}

    def on_record(run_dir: str, record: dict) -> None:
        name = os.path.basename(os.path.normpath(run_dir)) if per_member else ""
        if name not in writers:
            writers[name] = MetricsWriter(os.path.join(log_dir, name))
        writers[name].write(record)

    try:
        yield on_record
    finally:
        for writer in writers.values():
            writer.close()


def convert(metrics_path: str, log_dir: str) -> int:
    """Write every record of ``metrics_path`` (a ``metrics.jsonl``) as event files under ``log_dir``;
    returns the number of records written (lines without ``episodes`` are skipped)."""
    n = 0
    with open(metrics_path) as fh, MetricsWriter(log_dir) as writer:
        for line in fh:
            line = line.strip()
            if not line:
                continue
            record = json.loads(line)
            if STEP_KEY in record:
                writer.write(record)
                n += 1
    return n


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m splid_jax.tensorboard", description=__doc__.splitlines()[0])
    p.add_argument("metrics", metavar="METRICS.jsonl")
    p.add_argument("log_dir", metavar="OUT_DIR")
    a = p.parse_args(argv)
    try:
        n = convert(a.metrics, a.log_dir)
    except (OSError, TensorBoardUnavailable, json.JSONDecodeError) as err:
        print(f"{p.prog}: error: {err}", file=sys.stderr)
        return 2
    print(f"{n} records of {a.metrics} written to {a.log_dir}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
