"""From a figure's run directories to its series: each method's (or swept value's) members averaged
over the evaluations they all reached, with the standard error over seeds."""

from __future__ import annotations

import dataclasses
import os
from typing import Any

import numpy as np

from splid_jax import plot
from splid_jax.common import stats
from splid_jax.figures.record import sweeps
from splid_jax.figures.registry import METHODS, SHORT, SPECS


@dataclasses.dataclass(frozen=True)
class Series:
    method: str
    value: Any  # the swept field's value, or None
    label: str
    seeds: int
    columns: dict[str, np.ndarray]  # iteration, episodes, wall_s: per evaluation
    mean: dict[str, np.ndarray]
    sem: dict[str, np.ndarray]  # standard error of the mean over seeds (nan for one seed)


MEASURES = ("eval_success", "eval_success_final", "eval_return")


def her_settings(config: dict) -> str | None:
    """Whose settings a HER run's config.json records: "mrl", "Baselines", or None."""
    from splid_jax.config import TrainConfig
    from splid_jax.learners.her.config import settings_name

    if config.get("algo") != "her":
        return None
    return settings_name(TrainConfig.from_json(config).learner_config())


def load_series(out: str, record: dict) -> list[Series]:
    """Each method's members from its sweeps' directories, grouped by the swept value, over the evaluations
    every member of the group reached."""
    spec = SPECS[record["figure"]]
    runs_of: dict[str, list[plot.Run]] = {method: [] for method in record["methods"]}
    for method, ran, sub in sweeps(record):
        for member in ran["members"]:
            try:
                run = plot.load_run(os.path.join(out, sub, member["run_dir"]))
            except plot.PlotError:
                continue  # not trained yet, or stopped before its first evaluation
            # a member without its config.json (results kept lean) is described by the figure's record
            runs_of[method].append(run if run.config else dataclasses.replace(run, config=member))
    series = []
    for method, runs in runs_of.items():
        groups: dict[Any, list[plot.Run]] = {}
        for run in runs:
            groups.setdefault(run.config.get(spec.vary) if spec.vary else None, []).append(run)
        for value, members in sorted(groups.items(), key=lambda kv: (kv[0] is None, kv[0])):
            columns_of = [r.columns for r in members]
            common = stats.common_iterations(columns_of)
            if not common:
                continue
            stacked = stats.aligned(columns_of, (*MEASURES, "episodes", "wall_s"), common)
            n = len(members)
            sem = {k: stats.sem(stacked[k]) for k in MEASURES}
            label = METHODS[method].label if not spec.vary else f"{SHORT[spec.vary]} = {value:g}"
            if members[0].config.get("algo") == "gcsl":
                label += f" ({members[0].config.get('gcsl_relabel')}-state relabelling)"
            whose = her_settings(members[0].config) if method == "her" else None
            if whose:
                label += f" ({whose})"
            planned = members[0].config.get("iterations")
            if planned is not None and common[-1] < planned:  # a curve that ends early says so in the legend
                label += f", stopped at {int(stacked['episodes'][0][-1]):,} episodes"
            columns = {
                "iteration": np.asarray(common),
                "episodes": stacked["episodes"][0],
                "wall_s": stats.mean(stacked["wall_s"]),
            }
            series.append(Series(method, value, label, n, columns, {k: stats.mean(stacked[k]) for k in MEASURES}, sem))
    return series
