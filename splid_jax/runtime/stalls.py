"""A chunk that runs far longer than the slowest before it is reported as a possibly stalled device: the run
goes on waiting, and the user learns that Ctrl-C saves and stops."""

from __future__ import annotations

# A chunk that runs this many times longer than the slowest before it, and at least LATE_FLOOR_S, is late.
LATE_FACTOR, LATE_FLOOR_S = 10.0, 60.0


def late_after(slowest_s: float) -> float | None:
    """Seconds after which a chunk counts as late: none before one has finished, since the first
    takes as long as it takes."""
    return None if slowest_s <= 0 else max(LATE_FLOOR_S, LATE_FACTOR * slowest_s)


def late_message(cfg, iteration: int, ran_s: float, slowest_s: float) -> str:
    span = f"{iteration + 1}-{iteration + cfg.eval_every}"
    return (
        f"{cfg.run_dir}: iterations {span} have run {ran_s:.0f} s, {ran_s / slowest_s:.0f}x the slowest chunk "
        f"before them ({slowest_s:.1f} s); the device may be stalled (Ctrl-C saves iteration {iteration} and stops)"
    )
