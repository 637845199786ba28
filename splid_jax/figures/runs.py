"""Training a figure: each method's vmapped sweep through the one host loop, in OUT/METHOD/."""

from __future__ import annotations

import os
import time

from splid_jax.config import TrainConfig
from splid_jax.figures.record import SPEC, sweeps
from splid_jax.runtime import loop, progress, run_files


def train(out: str, record: dict, quiet: bool, resume: bool = False) -> None:
    """Trains each method's sweep in turn (on ``resume``, those with a checkpoint from it), noting in
    OUT/figure.json the seconds each took over every call, a stopped one's included."""
    loop.write_json(os.path.join(out, SPEC), record)
    for method, ran, sub in sweeps(record):
        t0 = time.perf_counter()
        try:
            train_sweep(out, record, method, ran, sub, quiet, resume)
        finally:  # a stopped method's seconds count too, so a resumed figure's total is whole
            ran["total_s"] = round(ran.get("total_s", 0.0) + time.perf_counter() - t0, 1)  # compilation included
            loop.write_json(os.path.join(out, SPEC), record)


def train_sweep(out: str, record: dict, method: str, ran: dict, sub: str, quiet: bool, resume: bool) -> None:
    """One method's sweep in OUT/``sub`` (on ``resume`` from its checkpoint, if it has one)."""
    run_dir = os.path.join(out, sub)
    base = TrainConfig.from_json({**ran["config"], "run_dir": run_dir})
    lanes = [TrainConfig.from_json({**m, "run_dir": os.path.join(run_dir, m["run_dir"])}) for m in ran["members"]]
    again = resume and run_files.holds_run(run_dir)  # started: from its checkpoint, or again
    progress.show(
        f"{record['figure']} {method}: {len(lanes)} members, {base.iterations} iterations x "
        f"{ran['episodes_per_iteration']} episodes = {ran['episodes']:,} episodes "
        f"(budget {record['budget_episodes']:,})" + (", resumed" if again else ""),
        quiet,
    )
    env = base.make_env()
    loop.run(base, env, members=lanes, resume=again, quiet=quiet)
