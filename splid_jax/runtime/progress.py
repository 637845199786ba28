"""One terminal line per chunk (per sweep chunk: one summary line), from the metrics.jsonl record."""

from __future__ import annotations

import contextlib
import json
import os
import sys


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
