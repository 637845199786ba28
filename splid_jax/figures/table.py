"""A figure's CSV: one row per series and evaluation, with what each method ran in all."""

from __future__ import annotations

import csv
import math
from collections.abc import Sequence
from typing import Any

from splid_jax.figures.record import sweeps
from splid_jax.figures.registry import SPECS
from splid_jax.figures.series import MEASURES, Series


def write_csv(path: str, series: Sequence[Series], record: dict) -> None:
    """One row per series and evaluation; the run columns say what each method ran in all."""
    spec = SPECS[record["figure"]]
    head = ["method", *([spec.vary] if spec.vary else []), "iteration", "episodes"]
    head += [f"{m}_{s}" for m in MEASURES for s in ("mean", "sem")]
    head += ["seeds", "wall_s", "episodes_per_iteration", "run_iterations", "run_episodes", "budget_episodes"]
    # the sweep that trained each series: a merged Figure 4 or 5 holds one per part
    ran_of = {(k, m.get(spec.vary) if spec.vary else None): r for k, r, _ in sweeps(record) for m in r["members"]}
    with open(path, "w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(head)
        for s in series:
            ran = ran_of[s.method, s.value]
            for i in range(len(s.columns["iteration"])):
                row: list[Any] = [s.method, *([s.value] if spec.vary else [])]
                row += [int(s.columns["iteration"][i]), int(s.columns["episodes"][i])]
                for m in MEASURES:
                    row += [f"{s.mean[m][i]:.6g}", "" if math.isnan(s.sem[m][i]) else f"{s.sem[m][i]:.6g}"]
                row += [
                    s.seeds,
                    f"{s.columns['wall_s'][i]:.1f}",
                    ran["episodes_per_iteration"],
                    ran["iterations"],
                    ran["episodes"],
                    record["budget_episodes"],
                ]
                writer.writerow(row)
