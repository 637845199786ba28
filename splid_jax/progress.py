"""One terminal line per chunk, and the metrics.jsonl record behind it."""

from __future__ import annotations

import sys


def _si(x: float) -> str:
    for unit, scale in (("G", 1e9), ("M", 1e6), ("k", 1e3)):
        if abs(x) >= scale:
            return f"{x / scale:.1f}{unit}"
    return f"{x:.0f}"


HEADER = (
    f"{'iter':>9} {'episodes':>9} {'env st':>7} {'select st':>9} {'steps/s':>8} {'success':>7} {'final':>6} "
    f"{'return':>7} {'buffer':>6} {'accept':>6} {'bc loss':>8} {'wall s':>7}"
)


def line(rec: dict, total_iterations: int) -> str:
    pairs = max(rec["select_pairs"], 1)
    return (
        f"{rec['iteration']:>4}/{total_iterations:<4} {rec['episodes']:>9,} {_si(rec['env_steps']):>7} "
        f"{_si(rec['select_steps']):>9} {_si(rec['steps_per_s']):>8} {rec['eval_success']:>7.3f} "
        f"{rec['eval_success_final']:>6.3f} {rec['eval_return']:>7.2f} {rec['buffer_fill']:>6.1%} "
        f"{rec['select_accepted'] / pairs:>6.1%} {rec['bc_loss']:>8.4f} {rec['wall_s']:>7.1f}"
    )


def show(text: str, quiet: bool = False) -> None:
    if not quiet:
        print(text, file=sys.stdout, flush=True)
