"""``python -m splid_jax.figures FIG --env ENV``: the paper's figures, each from one command.

Every series is trained through the one host loop (``splid_jax.runtime.loop``) as one vmapped sweep whose
members are the seeds (and, for Figures 4 and 5, the values of H or sigma), in OUT/METHOD/. Every
method gets the same budget of exploration episodes: its iterations are the budget over its
episodes per iteration, rounded to whole compiled chunks, and the CSV says what each one ran. The
figure and its CSV are drawn from the run directories alone, so ``--replot`` redraws them without
training; OUT/figure.json records the command, the device and the date."""

from __future__ import annotations

from splid_jax.cli import exit_with, quiet_interrupts

if __name__ == "__main__":  # a signal while JAX loads ends the process with one line, no traceback
    quiet_interrupts()

import argparse  # noqa: E402
import contextlib  # noqa: E402
import csv  # noqa: E402
import dataclasses  # noqa: E402
import datetime  # noqa: E402
import io  # noqa: E402
import json  # noqa: E402
import math  # noqa: E402
import os  # noqa: E402
import shlex  # noqa: E402
import shutil  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from collections.abc import Sequence  # noqa: E402
from typing import Any  # noqa: E402

import matplotlib  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402
from matplotlib.ticker import EngFormatter  # noqa: E402

import envs  # noqa: E402
from splid_jax import plot  # noqa: E402
from splid_jax.cli import Parser, add_compile_cache_flag, use_compile_cache  # noqa: E402
from splid_jax.common.errors import InvalidConfig, check  # noqa: E402
from splid_jax.common.values import read_value, typed_value  # noqa: E402
from splid_jax.config import TASK_DEFAULTS, TrainConfig  # noqa: E402
from splid_jax.learners import registry  # noqa: E402
from splid_jax.runtime import checkpoint, lock, loop, progress  # noqa: E402

SPEC = "figure.json"  # the figure's command, device, date and what each method ran


@dataclasses.dataclass(frozen=True)
class Method:
    label: str
    fields: dict[str, Any]  # the TrainConfig fields that make the method


METHODS: dict[str, Method] = {
    "splid": Method("SPLID", {"algo": "splid", "select": True}),
    "gcsl": Method("GCSL", {"algo": "gcsl"}),
    "pchid": Method("PCHID", {"algo": "pchid"}),
    "her": Method("HER (DDPG + HER)", {"algo": "her"}),
    "es": Method("ES (OpenAI-ES)", {"algo": "es"}),
    "no-select": Method("SPLID without SELECT", {"algo": "splid", "select": False}),
}


@dataclasses.dataclass(frozen=True)
class Spec:
    """What one figure trains and draws."""

    title: str
    methods: tuple[str, ...]  # the methods it trains, in legend order
    panels: tuple[tuple[str, str], ...]  # (metric, panel title)
    vary: str | None = None  # a config field whose values a sweep spans, one series each
    values: tuple = ()  # its values by default


SUCCESS = (("eval_success", "success at any step"), ("eval_success_final", "success at the final step"))
SPECS: dict[str, Spec] = {
    "fig3": Spec("SPLID against its baselines", tuple(METHODS), SUCCESS),
    "fig4": Spec("SPLID's learning horizon H", ("splid",), SUCCESS, "horizon", (1, 2, 4, 8, 16)),
    "fig5": Spec("SPLID's exploration factor sigma", ("splid",), SUCCESS, "sigma", (0.25, 0.5, 1.0, 2.0)),
    "fig6": Spec("SPLID with and without SELECT", ("splid", "no-select"), (("eval_return", "average return"),)),
}
# The paper's Figures 8 and 9 are the same runs (SPLID and GCSL on its appendix tasks) drawn as average
# return and as success: here one figure with both, made by either name.
SPECS["fig8"] = SPECS["fig9"] = Spec(
    "SPLID against GCSL", ("splid", "gcsl"), (("eval_return", "average return"),) + SUCCESS
)
SHORT = {"horizon": "H", "sigma": "sigma"}  # a swept field's name in member names and labels

# Exploration episodes per method by default (the paper's x axes); other tasks: their default run's.
BUDGETS = {"push": 20_000, "slide": 100_000, "pick_and_place": 100_000}
# Set by the figure itself, not through --set.
OWNED = frozenset({"env", "algo", "select", "seed", "iterations", "run_dir"})

# --quick: the point task, sizes that train six methods on a 2-core CPU in a few minutes.
QUICK_EPISODES = 320
QUICK_FIELDS: dict[str, Any] = dict(
    num_envs=16, eval_every=5, eval_episodes=50, bc_steps=20, batch_size=64, hidden=(32, 32), buffer_size=20_000
)
QUICK_METHOD_FIELDS: dict[str, dict[str, Any]] = {
    "her": dict(her_options="hidden=32,32,batch_size=64,n_batches=10,buffer_transitions=20000"),
    "es": dict(es_options="population=16"),
}


def reads(algo: str, field: str) -> bool:
    """Whether ``algo`` reads a TrainConfig field, so that a setting given for every method skips
    those that do not (ES's num_envs is its population's episodes)."""
    return registry.reads(algo, field)


def default_budget(env: str) -> int:
    """The task's budget: the paper's for the Fetch tasks, the default run's (iterations x envs) otherwise."""
    if env in BUDGETS:
        return BUDGETS[env]
    return TASK_DEFAULTS[env]["iterations"] * TASK_DEFAULTS[env]["num_envs"]


def parse_methods(text: str, allowed: Sequence[str]) -> tuple[str, ...]:
    words = tuple(w.strip() for w in text.split(","))
    bad = [w for w in words if w not in allowed]
    check(
        not bad and len(set(words)) == len(words) and words != ("",),
        "methods",
        text,
        "distinct names among " + ", ".join(allowed),
    )
    return words


def parse_sets(items: Sequence[str], methods: Sequence[str]) -> dict[str | None, dict[str, Any]]:
    """``[METHOD.]FIELD=VALUE`` items as {None: fields for every method, METHOD: its own fields}."""
    types = {f.name: f.type for f in dataclasses.fields(TrainConfig)}
    out: dict[str | None, dict[str, Any]] = {None: {}}
    for item in items:
        key, eq, value = item.partition("=")
        method, dot, name = key.rpartition(".")
        name = name.replace("-", "_")
        if not eq or (dot and method not in methods):
            allowed = "[METHOD.]FIELD=VALUE with METHOD among " + ", ".join(methods)
            raise InvalidConfig("set", item, allowed)
        check(
            name in types and name not in OWNED,
            "set",
            item,
            "a TrainConfig field other than " + ", ".join(sorted(OWNED)) + " (see python -m splid_jax.train --help)",
        )
        algo = METHODS[method].fields["algo"] if method else None
        check(not algo or reads(algo, name), "set", item, f"a field that {method} reads")
        kind = str(types[name])
        if kind.startswith("tuple"):  # one field per --set, so its commas are the tuple's
            value = value.replace(",", ":")
        elif kind != "str":
            value = read_value(value)
        out.setdefault(method or None, {})[name] = typed_value(name, kind, value)
    return out


# ---------------------------------------------------------------------------------------------
# What to train


@dataclasses.dataclass(frozen=True)
class Plan:
    """One method's vmapped sweep."""

    method: str
    base: TrainConfig
    lanes: tuple[TrainConfig, ...]
    episodes_per_iteration: int


def member_name(seed: int, vary: str | None, value) -> str:
    return f"s{seed}" if vary is None else f"{SHORT[vary]}{value:g}-s{seed}"


def plan(
    spec: Spec,
    env_name: str,
    methods: Sequence[str],
    seeds: int,
    budget: int,
    sets: dict[str | None, dict[str, Any]],
    out: str,
    values: Sequence = (),
    quick: bool = False,
) -> list[Plan]:
    """Each method's sweep: its config, its members and its iterations for ``budget`` episodes.
    Builds every method's learner, so a setting none accepts fails here, before any training."""
    check(seeds >= 1, "seeds", seeds, "an integer >= 1")
    check(budget >= 1, "episodes", budget, "an integer >= 1")
    values = tuple(values) or spec.values
    made: dict[str, envs.GoalEnv] = {}
    plans = []
    for name in methods:
        algo = METHODS[name].fields["algo"]
        shared = {**(QUICK_FIELDS if quick else {}), **sets.get(None, {})}
        fields = {"env": env_name, **{k: v for k, v in shared.items() if reads(algo, k)}}
        fields.update(QUICK_METHOD_FIELDS.get(name, {}) if quick else {}, **sets.get(name, {}), **METHODS[name].fields)
        if spec.vary:
            fields[spec.vary] = max(values)  # shapes for the largest H, as a sweep's
        if "eval_every" in fields:  # else the default iterations, a multiple of the default eval_every
            fields["iterations"] = fields["eval_every"]
        probe = TrainConfig(**fields, run_dir=os.path.join(out, name))
        options = probe.env_options
        if options not in made:
            made[options] = loop.make_env(env_name, **probe.env_overrides())
        env = made[options]
        probe.check_env(env)
        per_iteration = registry.make_algorithm(probe, env).counters(1, 0)["episodes"]
        chunks = max(1, math.floor(budget / (per_iteration * probe.eval_every) + 0.5))  # nearest, half up
        # pchid_every left at 0 is resolved again, so PCHID's schedule follows the figure's iterations
        base = dataclasses.replace(
            probe, iterations=chunks * probe.eval_every, pchid_every=fields.get("pchid_every", 0)
        )
        grid = [(s, v) for v in (values if spec.vary else (None,)) for s in range(seeds)]
        lanes = tuple(
            dataclasses.replace(
                base,
                seed=s,
                run_dir=os.path.join(base.run_dir, member_name(s, spec.vary, v)),
                **({spec.vary: v} if spec.vary else {}),
            )
            for s, v in grid
        )
        for lane in lanes:
            lane.check_env(env)
        registry.make_algorithm(base, env)  # the run's own settings
        plans.append(Plan(name, base, lanes, per_iteration))
    return plans


def device_name() -> str:
    import jax

    device = jax.devices()[0]
    if device.platform == "cpu":
        return f"CPU ({os.cpu_count()} cores)"
    return device.device_kind


def check_out(out: str) -> None:
    if os.path.isdir(out) and set(os.listdir(out)) - {lock.LOCK}:
        raise InvalidConfig("out", out, "a new or empty directory (--replot redraws the figure in it)")
    check(not os.path.exists(out) or os.path.isdir(out), "out", out, "a directory, not a file")
    loop.check_writable(out)


def describe(plans: Sequence[Plan]) -> dict:
    """What each method runs, as OUT/figure.json keeps it: enough to resume or redraw the figure."""
    return {
        p.method: {
            "iterations": p.base.iterations,
            "episodes_per_iteration": p.episodes_per_iteration,
            "episodes": p.base.iterations * p.episodes_per_iteration,
            "config": {**p.base.to_json(), "run_dir": None},
            "members": [{**m.to_json(), "run_dir": os.path.basename(m.run_dir)} for m in p.lanes],
        }
        for p in plans
    }


def sweeps(record: dict) -> list[tuple[str, dict, str]]:
    """Each vmapped sweep of the figure as (method, its record, its directory under OUT): one per method
    in METHOD/, or, in a Figure 4 or 5 merged from parts trained with distinct values, one per part in
    METHOD/PART/."""
    found = []
    for method in record["methods"]:
        ran = record["runs"][method]
        for part in ran.get("parts", [ran]):
            found.append((method, part, os.path.join(method, *([part["dir"]] if "dir" in part else []))))
    return found


def train(out: str, record: dict, quiet: bool, resume: bool = False) -> None:
    """Trains each method's sweep in turn (on ``resume``, those with a checkpoint from it), noting in
    OUT/figure.json the seconds each took over every call, a stopped one's included."""
    loop.write_json(os.path.join(out, SPEC), record)
    for method, ran, sub in sweeps(record):
        run_dir = os.path.join(out, sub)
        base = TrainConfig(**{**ran["config"], "run_dir": run_dir})
        lanes = [TrainConfig(**{**m, "run_dir": os.path.join(run_dir, m["run_dir"])}) for m in ran["members"]]
        again = resume and os.path.isdir(run_dir) and checkpoint.latest_step(run_dir) is not None
        progress.show(
            f"{record['figure']} {method}: {len(lanes)} members, {base.iterations} iterations x "
            f"{ran['episodes_per_iteration']} episodes = {ran['episodes']:,} episodes "
            f"(budget {record['budget_episodes']:,})" + (", resumed" if again else ""),
            quiet,
        )
        t0 = time.perf_counter()
        try:
            env = loop.make_env(base.env, **base.env_overrides())
            loop.run(base, env, members=lanes, resume=again, quiet=quiet)
        finally:  # a stopped method's seconds count too, so a resumed figure's total is whole
            ran["total_s"] = round(ran.get("total_s", 0.0) + time.perf_counter() - t0, 1)  # compilation included
            loop.write_json(os.path.join(out, SPEC), record)


def merge(out: str, parts: Sequence[str], figure: str, command: str) -> dict:
    """One figure from parts of it trained apart (other machines, calls or processes): Figure 3's
    ``--methods`` subsets, or Figure 4's or 5's ``--values`` subsets, each then a sweep of its own
    shapes (an H sweep replays every member at its largest H's cost). Each part's method directories are
    copied into ``out`` (checkpoints too, so ``--resume`` continues an unfinished one) and their records
    joined; the parts stay as they are."""
    check(len(parts) >= 2, "merge", " ".join(parts), "two or more figure directories")
    records = [load_record(p, "merge") for p in parts]
    first, spec = records[0], SPECS[figure]
    check(first["figure"] == figure, "merge", parts[0], f"a {figure} directory")
    for part, record in zip(parts, records, strict=True):
        for key in ("figure", "env", "seeds", "budget_episodes"):
            check(
                record.get(key) == first.get(key),
                "merge",
                part,
                f"a figure directory with the {key} of {parts[0]} ({first.get(key)!r})",
            )
        merged_before = any("parts" in ran for ran in record["runs"].values())
        check(not merged_before, "merge", part, "a figure directory one command trained, not a merged one")
    joined = " ".join(parts)
    if spec.vary:
        values = [m[spec.vary] for r in records for ran in r["runs"].values() for m in ran["members"]]
        distinct = len(set(values)) * first["seeds"] == len(values)
        check(distinct, "merge", joined, f"directories that train distinct {SHORT[spec.vary]} values")
        methods = list(spec.methods)
    else:
        methods = [m for r in records for m in r["methods"]]
        check(len(set(methods)) == len(methods), "merge", joined, "directories that train distinct methods")
    check_out(out)
    os.makedirs(out, exist_ok=True)
    runs: dict[str, dict] = {}
    for i, (part, record) in enumerate(zip(parts, records, strict=True)):
        for method in record["methods"]:
            sub = [f"part{i}"] if spec.vary else []
            if os.path.isdir(os.path.join(part, method)):
                shutil.copytree(os.path.join(part, method), os.path.join(out, method, *sub))
            if spec.vary:
                runs.setdefault(method, {"parts": []})["parts"].append({**record["runs"][method], "dir": sub[0]})
            else:
                runs[method] = record["runs"][method]
    merged = {
        **first,
        "methods": sorted(set(methods), key=spec.methods.index),
        "device": " + ".join(dict.fromkeys(r["device"] for r in records)),
        "date": " + ".join(dict.fromkeys(r["date"] for r in records)),
        "command": command,
        "runs": runs,
        "parts": [{k: r[k] for k in ("command", "device", "date", "methods")} for r in records],
    }
    loop.write_json(os.path.join(out, SPEC), merged)
    return merged


# ---------------------------------------------------------------------------------------------
# From the run directories to a figure


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


def load_record(out: str, field: str = "out") -> dict:
    """OUT/figure.json; a missing or unreadable one is blamed on ``field``, the flag that named OUT."""
    path = os.path.join(out, SPEC)
    try:
        with open(path) as fh:
            record = json.load(fh)
        check(isinstance(record, dict) and record.get("figure") in SPECS, field, out,
              f"a figure directory ({path} names no figure)")  # fmt: skip
        return record
    except (OSError, json.JSONDecodeError) as e:
        why = "" if isinstance(e, FileNotFoundError | json.JSONDecodeError) else f" ({e.strerror})"
        raise InvalidConfig(field, out, f"a directory holding the {SPEC} a figure command wrote{why}") from None


def check_unchanged(ns: argparse.Namespace, record: dict, out: str, mode: str) -> dict:
    """``record`` if the command asks for the figure it holds: --resume and --replot continue or redraw
    a figure as it was started, so a setting given anew must be the one it was started with."""
    check(ns.figure == record["figure"], "figure", ns.figure, f"{record['figure']}, the figure in {out}")
    started = {"env": record.get("env"), "seeds": record.get("seeds"), "episodes": record.get("budget_episodes")}
    with contextlib.suppress(SystemExit, ValueError, TypeError, KeyError), contextlib.redirect_stderr(io.StringIO()):
        first = build_parser().parse_args(shlex.split(record["command"])[3:])
        started |= {"set": first.set, "values": first.values, "methods": first.methods, "quick": first.quick}
    for name in ("env", "methods", "seeds", "episodes", "values", "set", "quick"):
        given, default = getattr(ns, name), build_parser().get_default(name)
        if given != default and given != started.get(name, default):
            was = started.get(name)
            allowed = f"{was!r} as the figure in {out} was started (--{mode} changes no setting)"
            raise InvalidConfig(name, given, allowed)
    return record


def load_series(out: str, record: dict) -> list[Series]:
    """Each method's members from its sweeps' directories, grouped by the swept value, over the evaluations
    every member of the group reached."""
    spec = SPECS[record["figure"]]
    runs_of: dict[str, list[plot.Run]] = {method: [] for method in record["methods"]}
    for method, ran, sub in sweeps(record):
        for member in ran["members"]:
            try:
                runs_of[method].append(plot.load_run(os.path.join(out, sub, member["run_dir"])))
            except plot.PlotError:
                continue  # not trained yet, or stopped before its first evaluation
    series = []
    for method, runs in runs_of.items():
        groups: dict[Any, list[plot.Run]] = {}
        for run in runs:
            groups.setdefault(run.config.get(spec.vary) if spec.vary else None, []).append(run)
        for value, members in sorted(groups.items(), key=lambda kv: (kv[0] is None, kv[0])):
            common = sorted(set.intersection(*(set(r.columns["iteration"].tolist()) for r in members)))
            if not common:
                continue
            at = [np.searchsorted(r.columns["iteration"], common) for r in members]
            stacked = {
                k: np.stack([r.columns[k][i] for r, i in zip(members, at, strict=True)])
                for k in (*MEASURES, "episodes", "wall_s")
            }
            n = len(members)
            sem = {
                k: stacked[k].std(0, ddof=1) / math.sqrt(n) if n > 1 else np.full(len(common), np.nan) for k in MEASURES
            }
            label = METHODS[method].label if not spec.vary else f"{SHORT[spec.vary]} = {value:g}"
            if members[0].config.get("algo") == "gcsl":
                label += f" ({members[0].config.get('gcsl_relabel')}-state relabelling)"
            columns = {
                "iteration": np.asarray(common),
                "episodes": stacked["episodes"][0],
                "wall_s": stacked["wall_s"].mean(0),
            }
            series.append(Series(method, value, label, n, columns, {k: stacked[k].mean(0) for k in MEASURES}, sem))
    return series


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


def title(record: dict, series: Sequence[Series]) -> str:
    spec = SPECS[record["figure"]]
    seeds = sorted({s.seeds for s in series})
    per = "setting" if spec.vary else "method"
    n = "-".join(str(k) for k in (seeds[0], seeds[-1]) if k) if len(seeds) > 1 else str(seeds[0])
    numbers = [name[3:] for name, other in SPECS.items() if other is spec]  # a figure drawn under two names
    figure = f"Figures {' and '.join(numbers)}" if len(numbers) > 1 else f"Figure {numbers[0]}"
    return (
        f"{figure}: {spec.title} on {record['env']}, {record['budget_episodes']:,} exploration "
        f"episodes per {per}\n{n} seeds per {per}, mean and standard error; {record['device']}, {record['date']}"
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
    draw(record, series).savefig(stem + ".png", dpi=120)
    missing = [m for m in record["methods"] if m not in {s.method for s in series}]
    if missing:
        progress.show(f"not drawn (no evaluation yet): {', '.join(missing)}", quiet)
    return stem + ".png", stem + ".csv"


# ---------------------------------------------------------------------------------------------
# Command line

HELP = """\
fig3: SPLID, GCSL, PCHID, HER, ES and SPLID without SELECT, success at any step and at the final step
      (GCSL pairs each step with the episode's last state, as the paper describes it: --set gcsl.gcsl_relabel=future
      for the original's future states).
fig4: SPLID with H in 1, 2, 4, 8, 16 (one sweep; every member replays at the largest H's cost: on an H100
      Slide's 25 members took 3.5x the time per member of Figure 5's at H = 8; --values subsets joined
      with --merge run each at its own cost).
fig5: SPLID with sigma in 0.25, 0.5, 1, 2 (one sweep).
fig6: average return of SPLID with and without SELECT.
fig8, fig9: SPLID and GCSL, average return (the paper's Figure 8) and success (Figure 9) from the same
      runs in one figure; the paper's tasks are point, reacher and sawyer_door.

Each method is one vmapped sweep in OUT/METHOD/ (the sweep's checkpoints, one run directory per
member); OUT/figure.json records the command, device, date and what each method ran; the PNG and the
CSV (method, episodes, mean and standard error of each measure, seeds, wall-clock seconds of training
without compilation, iterations and episodes each method ran) lie in OUT.
A figure too long for one machine or call can be trained as --methods (fig3) or --values (fig4, fig5)
subsets, each in its own --out, and joined with --merge (figN --merge DIR1 DIR2 ... --out OUT).
Exit codes: 0 done, 2 bad input (nothing trained), 3 a run stopped (NaN), 130 Ctrl-C, 143 SIGTERM
(each method's newest state is kept; --resume continues)."""


def build_parser() -> Parser:
    parser = Parser(
        prog="python -m splid_jax.figures",
        description="The paper's figures from one command each: every method trained with the same budget of "
        "exploration episodes through the one host loop, several seeds as one vmapped program, mean and standard "
        "error against episodes, a PNG and a CSV.",
        epilog=HELP,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("figure", choices=sorted(SPECS), help="which figure")
    parser.add_argument(
        "--env", default=None, help="task: " + ", ".join(envs.names()) + " (default push; fig8, fig9, --quick: point)"
    )
    parser.add_argument(
        "--methods", default=None, help="fig3: a comma-separated subset of " + ", ".join(METHODS) + " (default: all)"
    )
    parser.add_argument("--seeds", type=int, default=None, help="seeds per method or setting (default: 5)")
    parser.add_argument(
        "--episodes",
        type=int,
        default=None,
        metavar="N",
        help="exploration episodes per method (default: push 20,000, slide and pick_and_place "
        "100,000, other tasks their default run's; --quick: 320); each method's iterations are "
        "N / its episodes per iteration, rounded to whole chunks of eval_every iterations",
    )
    parser.add_argument(
        "--values", default=None, help="fig4: H values (default 1,2,4,8,16); fig5: sigma values (default 0.25,0.5,1,2)"
    )
    parser.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="[METHOD.]FIELD=VALUE",
        help="a training setting (a TrainConfig field, as python -m splid_jax.train --help lists "
        "them) for every method, or with METHOD. for one; repeatable",
    )
    parser.add_argument(
        "--quick",
        action="store_true",
        help="the point task with a tiny budget and small networks: the same code in a few minutes "
        "on a CPU (out: runs/DATE/FIG-point-quick)",
    )
    parser.add_argument(
        "--out", default=None, metavar="DIR", help="a new or empty directory (default experiments/results/DATE/FIG-ENV)"
    )
    parser.add_argument("--replot", action="store_true", help="redraw the figure and CSV in --out from its runs")
    parser.add_argument("--resume", action="store_true", help="continue the figure in --out where its runs stopped")
    parser.add_argument(
        "--merge",
        nargs="+",
        default=None,
        metavar="DIR",
        help="join figure directories trained with distinct --methods (fig3) or --values (fig4, fig5; each "
        "value then a sweep of its own shapes), on other machines or in other calls, into --out, a new "
        "directory, and draw them as one figure; the parts are copied, not moved",
    )
    parser.add_argument("--quiet", action="store_true", help="no progress display")
    add_compile_cache_flag(parser)
    return parser


def _values(spec: Spec, text: str | None) -> tuple:
    if text is None:
        return ()
    check(spec.vary is not None, "values", text, "given only for fig4 (H) or fig5 (sigma)")
    kind = int if spec.vary == "horizon" else float
    try:
        values = tuple(kind(w) for w in text.split(","))
    except ValueError:
        raise InvalidConfig("values", text, f"comma-separated {SHORT[spec.vary]} values") from None
    check(len(set(values)) == len(values), "values", text, "distinct values")
    return values


def main(argv: Sequence[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    parser = build_parser()
    ns = parser.parse_args(argv)
    spec = SPECS[ns.figure]
    today = datetime.date.today().isoformat()
    env_name = ns.env or ("point" if ns.quick or ns.figure in ("fig8", "fig9") else "push")
    out = ns.out or (
        os.path.join("runs", today, f"{ns.figure}-{env_name}-quick")
        if ns.quick
        else os.path.join("experiments", "results", today, f"{ns.figure}-{env_name}")
    )
    use_compile_cache(ns.compile_cache)
    try:
        with lock.hold(out, field="out"):  # one process per figure directory
            if ns.merge:
                check(not (ns.replot or ns.resume), "merge", " ".join(ns.merge), "given without --replot or --resume")
                check(ns.out is not None, "out", None, "the new directory --merge joins the parts into")
                merge(out, ns.merge, ns.figure, shlex.join(["python", "-m", "splid_jax.figures", *argv]))
            elif ns.replot or ns.resume:
                check(not (ns.replot and ns.resume), "replot", True, "given without --resume")
                mode = "resume" if ns.resume else "replot"
                record = check_unchanged(ns, load_record(out, mode), out, mode)
                if ns.resume:
                    train(out, record, ns.quiet, resume=True)
            else:
                check(env_name in envs.names(), "env", env_name, "one of " + ", ".join(envs.names()))
                check(not ns.quick or env_name == "point", "env", env_name, "point with --quick")
                if ns.methods is None:
                    methods = spec.methods
                else:
                    check(ns.figure == "fig3", "methods", ns.methods, "given only for fig3")
                    methods = parse_methods(ns.methods, spec.methods)
                budget = ns.episodes
                if budget is None:
                    budget = QUICK_EPISODES if ns.quick else default_budget(env_name)
                sets = parse_sets(ns.set, methods)
                values = _values(spec, ns.values)
                check_out(out)
                seeds = 5 if ns.seeds is None else ns.seeds
                plans = plan(spec, env_name, methods, seeds, budget, sets, out, values, ns.quick)
                record = {
                    "figure": ns.figure,
                    "env": env_name,
                    "methods": list(methods),
                    "seeds": seeds,
                    "budget_episodes": budget,
                    "device": device_name(),
                    "date": today,
                    "command": shlex.join(["python", "-m", "splid_jax.figures", *argv]),
                    "runs": describe(plans),
                }
                os.makedirs(out, exist_ok=True)
                train(out, record, ns.quiet)
            png, table = render(out, ns.quiet)
    except InvalidConfig as err:
        print(f"{parser.prog}: error: {err}", file=sys.stderr)
        return 2
    except loop.Interrupted as stop:
        progress.show(f"stopped; continue with: python -m splid_jax.figures {ns.figure} --out {out} --resume", ns.quiet)
        return stop.exit_code
    except (loop.RunStopped, checkpoint.CheckpointError) as err:
        print(f"{parser.prog}: error: {err}", file=sys.stderr)
        return 3
    except OSError as err:  # a file of the figure's own (figure.json, the PNG) on a full disk
        if not checkpoint.is_no_space(err):
            raise
        print(f"{parser.prog}: error: no space left on the device ({err.filename or out})", file=sys.stderr)
        return 3
    progress.show(f"figure: {png}\ntable: {table}", ns.quiet)
    return 0


if __name__ == "__main__":
    exit_with(main())
