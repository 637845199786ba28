"""A figure's PNG: one panel per measure, each series' mean over seeds with its standard error band."""

from __future__ import annotations

import os
from collections.abc import Sequence

import matplotlib
import numpy as np
from matplotlib.figure import Figure
from matplotlib.ticker import EngFormatter

from splid_jax.common.errors import check
from splid_jax.common.images import save_figure
from splid_jax.figures.record import load_record
from splid_jax.figures.registry import SPECS
from splid_jax.figures.series import Series, load_series
from splid_jax.figures.table import write_csv
from splid_jax.runtime import progress


def title(record: dict, series: Sequence[Series]) -> str:
    spec = SPECS[record["figure"]]
    seeds = sorted({s.seeds for s in series})
    per = "setting" if spec.vary else "method"
    n = "-".join(str(k) for k in (seeds[0], seeds[-1]) if k) if len(seeds) > 1 else str(seeds[0])
    numbers = [name[3:] for name, other in SPECS.items() if other is spec]  # a figure drawn under two names
    figure = f"Figures {' and '.join(numbers)}" if len(numbers) > 1 else f"Figure {numbers[0]}"
    return (
        f"{figure}: {spec.title} on {record['env']}, {record['budget_episodes']:,} exploration "
        f"episodes per {per}\n{n} seed{'s' * (seeds != [1])} per {per}, mean and standard error; "
        f"{record['device']}, {record['date']}"
    )


def draw(record: dict, series: Sequence[Series]) -> Figure:
    spec = SPECS[record["figure"]]
    fig = Figure(figsize=(max(9.0, 6.5 * len(spec.panels)), 5.2), layout="constrained")
    returns = [metric == "eval_return" for metric, _ in spec.panels]
    axes = np.atleast_1d(fig.subplots(1, len(spec.panels), sharey=len(set(returns)) == 1))
    cmap = matplotlib.colormaps["tab10"]
    for i, s in enumerate(series):
        x = s.columns["episodes"]
        one = len(x) == 1  # a single evaluation is a point: a line through it alone draws nothing
        for ax, (metric, _) in zip(axes, spec.panels, strict=True):
            ax.plot(
                x,
                s.mean[metric],
                color=cmap(i % 10),
                lw=1.8,
                marker="o" if one else None,
                label=f"{s.label} ({s.seeds} seed{'s' * (s.seeds > 1)})",
            )
            if not np.isnan(s.sem[metric]).all():
                lo, hi = s.mean[metric] - s.sem[metric], s.mean[metric] + s.sem[metric]
                ax.fill_between(x, lo, hi, color=cmap(i % 10), alpha=0.2, lw=0)
    for ax, (metric, name) in zip(axes, spec.panels, strict=True):
        ax.set_title(name)
        ax.set_xlabel("exploration episodes")
        ax.xaxis.set_major_formatter(EngFormatter(sep=""))
        ax.grid(alpha=0.3)
        if metric != "eval_return":
            ax.set_ylim(-0.02, 1.02)
    for i, (ax, is_return) in enumerate(zip(axes, returns, strict=True)):
        if i == 0 or is_return != returns[i - 1]:  # each new scale names itself
            ax.set_ylabel("average return" if is_return else "evaluation success rate")
    handles, names = axes[0].get_legend_handles_labels()
    if handles:
        fig.legend(handles, names, loc="outside lower center", ncols=min(len(names), 3), fontsize="small")
    fig.suptitle(title(record, series))
    return fig


def render(out: str, quiet: bool = False) -> tuple[str, str]:
    """The figure and its CSV from the run directories under ``out``; returns their paths."""
    record = load_record(out)
    series = load_series(out, record)
    check(bool(series), "out", out, "a figure directory with at least one evaluation in its runs")
    stem = os.path.join(out, f"{record['figure']}-{record['env']}")
    write_csv(stem + ".csv", series, record)
    save_figure(draw(record, series), stem + ".png", dpi=120)
    missing = [m for m in record["methods"] if m not in {s.method for s in series}]
    if missing:
        progress.show(f"not drawn (no evaluation yet): {', '.join(missing)}", quiet)
    return stem + ".png", stem + ".csv"
