"""``python -m splid_jax.figures``: its flags, its help, and what each exit code means."""

from __future__ import annotations

import argparse
import contextlib
import datetime
import io
import os
import shlex
import sys
from collections.abc import Sequence

import envs
from splid_jax.cli import Parser, add_compile_cache_flag, flag_error, interrupts_now, use_compile_cache
from splid_jax.common.errors import InvalidConfig, check
from splid_jax.figures.drawing import render
from splid_jax.figures.merging import merge
from splid_jax.figures.planning import QUICK_EPISODES, default_budget, describe, device_name, plan
from splid_jax.figures.record import check_out, load_record
from splid_jax.figures.registry import METHODS, SPECS
from splid_jax.figures.runs import train
from splid_jax.figures.settings import parse_methods, parse_sets, parse_values
from splid_jax.figures.side_by_side import share_gpu_memory, train_side_by_side
from splid_jax.runtime import checkpoint, lock, loop, progress

HELP = """\
fig3: SPLID, GCSL, PCHID, HER, ES and SPLID without SELECT, success at any step and at the final step
      (GCSL pairs each step with the episode's last state, as the paper describes it: --set gcsl.gcsl_relabel=future
      for the original's future states).
fig4: SPLID with H in 1, 2, 4, 8, 16 (one sweep; every member replays at the largest H's cost, so a
      member takes several times as long as at H = 8 alone; --values subsets joined with --merge run
      each at its own cost).
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
fig3 --side-by-side trains its methods at once, one process each: on a GPU under CUDA MPS
(nvidia-cuda-mps-control -d) they share it, where in turn their times add up; on several GPUs each
process takes one, the heaviest first, and HER's and SPLID's seeds are split while GPUs are to spare.
Exit codes: 0 done, 2 bad input (nothing trained), 3 a run stopped (NaN, a full or read-only disk), 130 Ctrl-C,
143 SIGTERM (each method's newest state is kept; --resume continues)."""


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
        "--methods",
        default=None,
        help="fig3: a comma-separated list among " + ", ".join(METHODS) + " (default: all but her-baselines, "
        "HER at OpenAI Baselines' settings, the paper's, to draw beside the default HER at mrl's)",
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
    parser.add_argument(
        "--resume",
        action="store_true",
        help="continue the figure in --out where its runs stopped, side by side if it was started so",
    )
    parser.add_argument(
        "--merge",
        nargs="+",
        default=None,
        metavar="DIR",
        help="join figure directories trained with distinct --methods (fig3) or --values (fig4, fig5; each "
        "value then a sweep of its own shapes), on other machines or in other calls, into --out, a new "
        "directory, and draw them as one figure; the parts are copied, not moved",
    )
    parser.add_argument(
        "--replace",
        action="store_true",
        help="with fig3's --merge: a method in several parts is taken from the last of them (a method run "
        "again, joined with an earlier merged figure)",
    )
    parser.add_argument(
        "--side-by-side",
        action="store_true",
        help="fig3: train the methods at once, one process each, their output in OUT/logs/ (on a GPU, under "
        "CUDA MPS: nvidia-cuda-mps-control -d; without it a GPU runs one process at a time, no faster than in turn; "
        "on several GPUs, one GPU per process, split by seed while GPUs are to spare)",
    )
    parser.add_argument("--quiet", action="store_true", help="no progress display")
    add_compile_cache_flag(parser)
    return parser


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
    if ns.side_by_side:  # before this process first touches the GPU
        share_gpu_memory()
    try:
        with lock.hold(out, field="out"):  # one process per figure directory
            check(bool(ns.merge) or not ns.replace, "replace", True, "given with --merge")
            side = ns.side_by_side
            check(not side or ns.figure == "fig3", "side_by_side", True, "given for fig3 (one process per method)")
            training = not (ns.merge or ns.replot)
            check(not side or training, "side_by_side", True, "given to train (not with --merge or --replot)")
            if ns.merge:
                check(not (ns.replot or ns.resume), "merge", " ".join(ns.merge), "given without --replot or --resume")
                check(ns.out is not None, "out", None, "the new directory --merge joins the parts into")
                merge(out, ns.merge, ns.figure, shlex.join(["python", "-m", "splid_jax.figures", *argv]), ns.replace)
            elif ns.replot or ns.resume:
                check(not (ns.replot and ns.resume), "replot", True, "given without --resume")
                mode = "resume" if ns.resume else "replot"
                record = check_unchanged(ns, load_record(out, mode), out, mode)
                if ns.resume:
                    first = started_command(record)  # a figure resumes as it was started: at once, or in turn
                    if not side and first is not None and first.side_by_side:
                        side = True
                        share_gpu_memory()  # nothing has touched the GPU yet
                    (train_side_by_side if side else train)(out, record, ns.quiet, resume=True)
            else:
                record = new_record(ns, spec, env_name, out, today, argv)
                (train_side_by_side if side else train)(out, record, ns.quiet)
            interrupts_now(f"after training ({out} is whole; --replot draws its figure)")
            png, table = render(out, ns.quiet)
    except InvalidConfig as err:
        print(f"{parser.prog}: error: {flag_error(err, parser)}", file=sys.stderr)
        return 2
    except loop.Interrupted as stop:
        progress.show(f"stopped; continue with: python -m splid_jax.figures {ns.figure} --out {out} --resume", ns.quiet)
        return stop.exit_code
    except (loop.RunStopped, checkpoint.CheckpointError) as err:
        print(f"{parser.prog}: error: {err}", file=sys.stderr)
        return 3
    except OSError as err:  # a file of the figure's own (figure.json, the PNG) on a full or read-only disk
        failure = checkpoint.write_failure(err)
        if failure is None:
            raise
        why = "no space left on the device" if checkpoint.is_no_space(err) else f"cannot write {out}: {failure[1]}"
        print(f"{parser.prog}: error: {why} ({err.filename or out})", file=sys.stderr)
        return 3
    progress.show(f"figure: {png}\ntable: {table}", ns.quiet)
    return 0


def new_record(ns: argparse.Namespace, spec, env_name: str, out: str, today: str, argv: list[str]) -> dict:
    """OUT/figure.json of a new figure, after its settings are checked; OUT is made, still empty."""
    check(env_name in envs.names(), "env", env_name, "one of " + ", ".join(envs.names()))
    check(not ns.quick or env_name == "point", "env", env_name, "point with --quick")
    if ns.methods is None:
        methods = spec.methods
    else:
        check(ns.figure == "fig3", "methods", ns.methods, "given only for fig3")
        methods = parse_methods(ns.methods, tuple(METHODS))
    budget = ns.episodes
    if budget is None:
        budget = QUICK_EPISODES if ns.quick else default_budget(env_name)
    sets = parse_sets(ns.set, methods)
    values = parse_values(spec, ns.values)
    check_out(out)
    seeds = 5 if ns.seeds is None else ns.seeds
    try:
        plans = plan(spec, env_name, methods, seeds, budget, sets, out, values, ns.quick)
    except InvalidConfig as err:  # a setting refused as its run's config is built: named as the user typed it
        if values and err.field == spec.vary:
            raise InvalidConfig("values", ns.values, err.allowed) from None
        typed = [item for item in ns.set if item.partition("=")[0].rpartition(".")[2].replace("-", "_") == err.field]
        if typed:
            raise InvalidConfig("set", typed[-1], err.allowed) from None
        raise
    os.makedirs(out, exist_ok=True)
    return {
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


def started_command(record: dict) -> argparse.Namespace | None:
    """The command that started the figure in ``record``, parsed as today's parser reads it; None where it no
    longer parses (a record of an older version)."""
    with contextlib.suppress(SystemExit, ValueError, TypeError, KeyError), contextlib.redirect_stderr(io.StringIO()):
        return build_parser().parse_args(shlex.split(record["command"])[3:])
    return None


def check_unchanged(ns: argparse.Namespace, record: dict, out: str, mode: str) -> dict:
    """``record`` if the command asks for the figure it holds: --resume and --replot continue or redraw
    a figure as it was started, so a setting given anew must be the one it was started with."""
    check(ns.figure == record["figure"], "figure", ns.figure, f"{record['figure']}, the figure in {out}")
    started = {"env": record.get("env"), "seeds": record.get("seeds"), "episodes": record.get("budget_episodes")}
    first = started_command(record)
    if first is not None:
        started |= {"set": first.set, "values": first.values, "methods": first.methods, "quick": first.quick}
    for name in ("env", "methods", "seeds", "episodes", "values", "set", "quick"):
        given, default = getattr(ns, name), build_parser().get_default(name)
        if given != default and given != started.get(name, default):
            was = started.get(name)
            allowed = f"{was!r} as the figure in {out} was started (--{mode} changes no setting)"
            raise InvalidConfig(name, given, allowed)
    return record
