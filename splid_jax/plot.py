"""``python -m splid_jax.plot RUN_DIR [RUN_DIR...]``: learning curves of one or more runs.

Rows: evaluation success (solid: at any step, dashed: at the final step) and evaluation
return. Columns: episodes, exploration env steps (``--steps all`` adds SELECT's replay steps, to
compare select and no-select runs at equal simulation cost) and wall-clock seconds.
"""

from __future__ import annotations

from splid_jax.cli import check_environment, exit_with, quiet_interrupts, run_main

if __name__ == "__main__":  # a signal while it loads or works ends the process with one line, no traceback
    quiet_interrupts("")
    check_environment()

import argparse  # noqa: E402
import dataclasses  # noqa: E402
import json  # noqa: E402
import os  # noqa: E402
import sys  # noqa: E402
from collections.abc import Sequence  # noqa: E402

import matplotlib  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.ticker import EngFormatter  # no pyplot: no global backend state, renders with Agg  # noqa: E402

from splid_jax.cli import Parser  # noqa: E402
from splid_jax.common import stats  # noqa: E402
from splid_jax.common.images import save_figure  # noqa: E402
from splid_jax.common.paths import unreadable  # noqa: E402
from splid_jax.common.stats import smooth  # noqa: E402
from splid_jax.config import PROVENANCE, TrainConfig  # noqa: E402
from splid_jax.learners import registry  # noqa: E402
from splid_jax.runtime import progress  # noqa: E402

DESCRIPTION = (
    "Learning curves of one or more runs: evaluation success (solid: at any step, dashed: at the final step) "
    "and return, against episodes, env steps and wall-clock seconds."
)
REQUIRED = (
    "iteration",
    "episodes",
    "env_steps",
    "select_steps",
    "eval_success",
    "eval_success_final",
    "eval_return",
    "wall_s",
)
# Config keys that never change what a run learns, so they neither label nor split runs.
_NOT_IDENTITY = {"run_dir", "seed", "checkpoint_every", *PROVENANCE}
_UNRECORDED = TrainConfig.unrecorded_values()  # a later setting, for the runs recorded before it
_STEP_AXES = {
    "env": ("env_steps", "exploration env steps"),
    "all": ("sim_steps", "simulator steps (env + SELECT replay)"),
}


def _x_axes(steps: str = "env") -> tuple[tuple[str, str], ...]:
    return (("episodes", "episodes"), _STEP_AXES[steps], ("wall_s", "wall clock (s)"))


class PlotError(ValueError):
    """A run directory cannot be plotted; the message is shown as is, exit code 2."""


@dataclasses.dataclass(frozen=True)
class Run:
    run_dir: str
    config: dict
    columns: dict[str, np.ndarray]  # metric name -> values per evaluation, in iteration order


def load_run(run_dir: str) -> Run:
    path = os.path.join(run_dir, "metrics.jsonl")
    for where in (run_dir, path):
        why = unreadable(where)
        if why:
            raise PlotError(f"{where}: cannot be read ({why})")
    if not os.path.isdir(run_dir):
        raise PlotError(f"{run_dir}: no such run directory")
    if not os.path.isfile(path):
        raise PlotError(f"{path}: no metrics file")
    records = progress.read_metrics(path, PlotError)
    if not records:
        raise PlotError(f"{path}: no evaluation records yet")
    for n, rec in enumerate(records, 1):
        missing = [k for k in REQUIRED if not isinstance(rec, dict) or k not in rec]
        if missing:
            raise PlotError(f"{path}: record {n} lacks {', '.join(missing)}")
    records.sort(key=lambda r: r["iteration"])
    columns = {k: np.asarray([float(r[k]) for r in records]) for k in REQUIRED}
    columns["sim_steps"] = columns["env_steps"] + columns["select_steps"]

    config: dict = {}
    config_path = os.path.join(run_dir, "config.json")
    if os.path.isfile(config_path):
        try:
            with open(config_path) as fh:
                loaded = json.load(fh)
            config = loaded if isinstance(loaded, dict) else {}
        except ValueError:  # not JSON, or not UTF-8: the label falls back to the directory name
            config = {}
    return Run(run_dir, config, columns)


def _dir_name(run: Run) -> str:
    return os.path.basename(os.path.normpath(run.run_dir))


def _fmt(key: str, value) -> str:
    if key == "select" and isinstance(value, bool):
        return "select" if value else "no-select"
    if isinstance(value, list):
        value = ",".join(str(v) for v in value)
    return f"{key}={value}"


def labels(runs: Sequence[Run]) -> tuple[list[str], list[str]]:
    """Per run: its label, and its label without the seed (the --group key).

    A label is ``env``, ``select``/``no-select``, any other setting that differs between
    the runs shown (a sweep's sigma or horizon), then ``s<seed>``; runs without a usable
    config.json are named by their directory.
    """
    configs = [r.config for r in runs if "env" in r.config]
    keys = sorted({k for c in configs for k in c} - _NOT_IDENTITY - {"env", "select"})
    value = lambda c, k: c.get(k, _UNRECORDED.get(k))  # noqa: E731
    varying = [k for k in keys if len({json.dumps(value(c, k), sort_keys=True) for c in configs}) > 1]
    full, group = [], []
    for run in runs:
        c = run.config
        if "env" not in c:
            full.append(_dir_name(run))
            group.append(_dir_name(run))
            continue
        parts = [str(c["env"])]
        algo = str(c.get("algo", "splid"))
        selects = algo not in registry.LEARNERS or registry.reads(algo, "select")  # HER, ES and GCSL do not
        if "select" in c and selects:
            parts.append(_fmt("select", c["select"]))
        parts += [_fmt(k, value(c, k)) for k in varying]
        group.append(" ".join(parts))
        full.append(" ".join(parts + ([f"s{c['seed']}"] if "seed" in c else [])))
    seen: dict[str, int] = {}
    for label in full:
        seen[label] = seen.get(label, 0) + 1
    full = [f"{label} ({_dir_name(r)})" if seen[label] > 1 else label for label, r in zip(full, runs, strict=True)]
    return full, group


@dataclasses.dataclass(frozen=True)
class Curve:
    label: str
    columns: dict[str, np.ndarray]  # mean over the runs it stands for
    low: dict[str, np.ndarray] | None = None  # min over runs (only for a group of several runs)
    high: dict[str, np.ndarray] | None = None


def _curves(runs: Sequence[Run], k: int, group: bool) -> list[Curve]:
    full, grouped = labels(runs)
    smoothed = [
        {**r.columns, **{m: smooth(r.columns[m], k) for m in ("eval_success", "eval_success_final", "eval_return")}}
        for r in runs
    ]
    if not group:
        return [Curve(label, cols) for label, cols in zip(full, smoothed, strict=True)]
    members: dict[str, list[dict[str, np.ndarray]]] = {}
    for key, cols in zip(grouped, smoothed, strict=True):
        members.setdefault(key, []).append(cols)
    curves = []
    for key, group_cols in members.items():
        if len(group_cols) == 1:
            curves.append(Curve(f"{key} (1 run)", group_cols[0]))
            continue
        stacked = stats.aligned(group_cols, group_cols[0], stats.common_iterations(group_cols))
        bands = {m: stats.band(v) for m, v in stacked.items()}
        curves.append(
            Curve(
                f"{key} ({len(group_cols)} runs)",
                {m: stats.mean(v) for m, v in stacked.items()},
                {m: low for m, (low, _) in bands.items()},
                {m: high for m, (_, high) in bands.items()},
            )
        )
    return curves


def _title(runs: Sequence[Run], curves: Sequence[Curve], k: int, group: bool) -> str:
    tasks = sorted({str(r.config["env"]) for r in runs if "env" in r.config})
    title = f"{', '.join(tasks) or _dir_name(runs[0])}: evaluation of {len(runs)} run{'s' * (len(runs) > 1)}"
    if group:
        title += f" in {len(curves)} group{'s' * (len(curves) > 1)}, min-max band over seeds"
    if k > 1:
        title += f", trailing mean over {k} evaluations"
    return title


def figure(runs: Sequence[Run], k: int = 1, group: bool = False, steps: str = "env") -> Figure:
    curves = _curves(runs, k, group)
    fig = Figure(figsize=(15, 8), layout="constrained")
    axes = fig.subplots(2, 3, sharey="row")
    cmap = matplotlib.colormaps["tab10" if len(curves) <= 10 else "tab20"]
    # A single evaluation is a point: a line through it alone would draw nothing, so it gets markers.
    single = [len(c.columns["iteration"]) == 1 for c in curves]
    markers = ("o", "v") if any(single) else (None, None)  # any step, final step
    for i, curve in enumerate(curves):
        color = cmap(i % cmap.N)
        for col, (x_key, _) in enumerate(_x_axes(steps)):
            x = curve.columns[x_key]
            for row, metrics in enumerate((("eval_success", "eval_success_final"), ("eval_return",))):
                ax = axes[row, col]
                for metric, style, marker in zip(metrics, ("-", "--"), markers, strict=False):
                    label = curve.label if (row, col, style) == (0, 0, "-") else None
                    marker = marker if single[i] else None
                    ax.plot(x, curve.columns[metric], style, color=color, label=label, lw=1.5, marker=marker)
                if curve.low is not None:
                    m = metrics[0]
                    ax.fill_between(x, curve.low[m], curve.high[m], color=color, alpha=0.2, lw=0)
    for col, (x_key, x_label) in enumerate(_x_axes(steps)):
        axes[1, col].set_xlabel(x_label)
        for row in range(2):
            axes[row, col].grid(alpha=0.3)
            if x_key != "wall_s":
                axes[row, col].xaxis.set_major_formatter(EngFormatter(sep=""))  # 400k, not 400000
    axes[0, 0].set_ylabel("eval success (solid: any step, dashed: final step)")
    axes[1, 0].set_ylabel("eval return")
    axes[0, 0].set_ylim(-0.02, 1.02)
    handles, names = axes[0, 0].get_legend_handles_labels()
    handles += [Line2D([], [], color="k", ls=style, marker=m) for style, m in zip(("-", "--"), markers, strict=True)]
    names += ["success at any step", "success at the final step"]
    # below the panels: long sweep labels would cover the curves inside an axis
    ncols = max(1, min(len(names), 150 // max(len(n) for n in names)))
    fig.legend(handles, names, loc="outside lower center", ncols=ncols, fontsize="small")
    fig.suptitle(_title(runs, curves, k, group))
    return fig


def _positive_int(text: str) -> int:
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be an integer >= 1, got {text}")
    return value


def build_parser() -> argparse.ArgumentParser:
    parser = Parser(prog="python -m splid_jax.plot", description=DESCRIPTION)
    parser.add_argument("run_dirs", nargs="+", metavar="RUN_DIR", help="run directory with metrics.jsonl")
    parser.add_argument("--out", metavar="FILE.png", help="output image (default: RUN_DIR/curves.png of the first, "
                        "redrawn each time)")
    parser.add_argument("--overwrite", action="store_true", help="replace an --out image that already exists")
    parser.add_argument("--smooth", type=_positive_int, default=1, metavar="K", help="trailing mean over K evals")
    parser.add_argument("--group", action="store_true", help="average runs that differ only in seed (min-max band)")
    parser.add_argument(
        "--steps", choices=sorted(_STEP_AXES), default="env", help="env: exploration steps; all: + SELECT"
    )
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    try:
        ns = parser.parse_args(argv)
    except SystemExit as e:  # argparse already printed usage or help
        return int(e.code or 0)
    try:
        runs = [load_run(d) for d in ns.run_dirs]
    except PlotError as e:
        print(f"{parser.prog}: error: {e}", file=sys.stderr)
        return 2
    out = ns.out or os.path.join(ns.run_dirs[0], "curves.png")
    formats = Figure().canvas.get_supported_filetypes()
    if os.path.splitext(out)[1].lstrip(".").lower() not in formats:
        why = "not an image file name (end it in .png, .pdf or .svg)"
        print(f"{parser.prog}: error: --out {out}: {why}", file=sys.stderr)
        return 2
    if ns.out is not None and os.path.exists(out) and not ns.overwrite:
        why = "a file that does not exist yet (or pass --overwrite)"
        print(f"{parser.prog}: error: --out {out}: {why}", file=sys.stderr)
        return 2
    try:
        if os.path.dirname(out):
            os.makedirs(os.path.dirname(out), exist_ok=True)
        save_figure(figure(runs, ns.smooth, ns.group, ns.steps), out, dpi=110)
    except OSError as e:
        print(f"{parser.prog}: error: cannot write {out}: {e.strerror or e}", file=sys.stderr)
        return 2
    progress.show(out)
    return 0


if __name__ == "__main__":
    exit_with(run_main(main))
