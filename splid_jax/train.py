"""``python -m splid_jax.train --env ENV``: train one run through the host loop (``splid_jax.runtime.loop``).

Exit codes: 0 done (or already complete), 2 a mistake in the command line (one line naming the
field, nothing written), 3 stopped (NaN, unreadable checkpoint, a full or read-only disk), 130 Ctrl-C,
143 SIGTERM; a stop by signal keeps the newest whole state as a checkpoint to --resume from."""

from __future__ import annotations

from splid_jax.cli import check_environment, exit_with, quiet_interrupts, run_main

if __name__ == "__main__":  # a signal while JAX loads ends the process with one line, no traceback
    quiet_interrupts()
    check_environment()

import argparse  # noqa: E402
import json  # noqa: E402
import os  # noqa: E402
import sys  # noqa: E402

import envs  # noqa: E402
from splid_jax.cli import (  # noqa: E402
    Parser,
    add_compile_cache_flag,
    add_config_flags,
    add_launch_flags,
    add_learner_flags,
    explicit_values,
    flag_error,
    interrupts_now,
    refuse_unread,
    start_processes,
    use_compile_cache,
)
from splid_jax.common.errors import InvalidConfig  # noqa: E402
from splid_jax.common.paths import unreadable  # noqa: E402
from splid_jax.config import PROVENANCE, RETIRED, TrainConfig  # noqa: E402
from splid_jax.presets import TUNED, TUNED_LEARNERS  # noqa: E402
from splid_jax.runtime import checkpoint, loop, multihost, progress  # noqa: E402
from splid_jax.runtime.loop import RunStopped  # noqa: E402
from splid_jax.runtime.run_files import EXPORT, MAY_CHANGE_ON_RESUME, SWEEP, env_settings  # noqa: E402

__all__ = ["RunStopped", "build_parser", "config_from_cli", "env_settings", "main", "run"]


def run(
    cfg: TrainConfig,
    env: envs.GoalEnv | None = None,
    resume: bool = False,
    quiet: bool = False,
    tensorboard: str | None = None,
) -> dict:
    """Train one run to ``cfg.iterations``; returns its last metrics record. ``tensorboard``: a
    directory that also receives every record as TensorBoard scalars."""
    from splid_jax.tensorboard import recording

    with recording(tensorboard) as on_record:
        return loop.run(cfg, env, resume=resume, quiet=quiet, on_record=on_record)[0]


def build_parser() -> argparse.ArgumentParser:
    parser = Parser(
        prog="python -m splid_jax.train",
        description="Train a goal-conditioned policy: SPLID (explore, SELECT by first hit time, behaviour "
        "cloning) or a baseline of the paper's comparison (--algo).",
        epilog="Exit codes: 0 done, 2 bad input (nothing written), 3 stopped on NaN, an unreadable checkpoint or a "
        "disk refusing a write (the last whole checkpoint kept), "
        "130 Ctrl-C, 143 SIGTERM (both keep the newest whole state as a checkpoint for --resume).",
    )
    add_config_flags(parser, TrainConfig, TUNED, per_algo=TUNED_LEARNERS)
    add_learner_flags(parser)
    parser.add_argument("--resume", metavar="RUN_DIR", help="continue the run saved in RUN_DIR (its config.json)")
    parser.add_argument("--quiet", action="store_true", help="no progress display")
    parser.add_argument(
        "--tensorboard",
        metavar="DIR",
        help="also write every evaluation's metrics as TensorBoard scalars under DIR, against episodes "
        '(needs pip install -e ".[tensorboard]")',
    )
    add_compile_cache_flag(parser)
    add_launch_flags(parser)
    return parser


def config_from_cli(ns: argparse.Namespace) -> tuple[TrainConfig, bool]:
    given = explicit_values(TrainConfig, ns)
    if ns.resume is None:
        refuse_unread(given, given.get("algo", "splid"), ns)
        return TrainConfig(**given), False
    if not ns.resume.strip():
        raise InvalidConfig("resume", ns.resume, "a run directory holding config.json")
    if given.get("run_dir", ns.resume) != ns.resume:  # the run continues where its checkpoints are
        raise InvalidConfig("run_dir", given["run_dir"], f"unset with --resume (the run continues in {ns.resume})")
    given.pop("run_dir", None)
    path = os.path.join(ns.resume, "config.json")
    why = unreadable(ns.resume) or unreadable(path)
    if why:
        raise InvalidConfig("resume", ns.resume, f"a run directory whose config.json can be read ({why})")
    if not os.path.isfile(path):
        raise InvalidConfig("resume", ns.resume, "a run directory holding config.json")
    if os.path.isfile(os.path.join(ns.resume, EXPORT)):
        why = f"a run train wrote, not an export without its buffer (its {EXPORT} names the run)"
        raise InvalidConfig("resume", ns.resume, why)
    sweep = os.path.dirname(os.path.abspath(ns.resume))
    if os.path.isfile(os.path.join(sweep, SWEEP)):  # its checkpoints are the sweep's: a run of its own would replace it
        why = f"a run train wrote, not a member of a sweep (continue it: python -m splid_jax.sweep --resume {sweep})"
        raise InvalidConfig("resume", ns.resume, why)
    names = {f.name for f in TrainConfig.settings_fields()}
    try:
        with open(path) as fh:
            saved = json.load(fh)
        unknown = (
            sorted(set(saved) - names - set(PROVENANCE) - set(RETIRED))
            if isinstance(saved, dict)
            else ["(not an object)"]
        )
    except (OSError, ValueError):  # unreadable, not UTF-8, not JSON
        unknown = ["(not JSON)"]
    if unknown:
        raise InvalidConfig("resume", ns.resume, f"a run whose config.json this version wrote (it has {unknown[0]})")
    for k, v in given.items():
        if k not in MAY_CHANGE_ON_RESUME and v != saved.get(k) and not (isinstance(v, tuple) and list(v) == saved[k]):
            raise InvalidConfig(k, v, f"{saved.get(k)!r} as in the run being resumed (only iterations may change)")
    refuse_unread(given, saved.get("algo", "splid"), ns)
    return TrainConfig.from_json(saved, **given, run_dir=ns.resume), True


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    ns = parser.parse_args(argv)
    use_compile_cache(ns.compile_cache)
    try:
        start_processes(ns)
        cfg, resume = multihost.from_first(lambda: config_from_cli(ns))  # its --resume directory: process 0's
        env = cfg.make_env()
        cfg.check_env(env)
        rec = run(cfg, env, resume=resume, quiet=ns.quiet, tensorboard=ns.tensorboard)
        interrupts_now(f"after the run completed ({cfg.run_dir} is whole)")
    except InvalidConfig as err:
        print(f"{parser.prog}: error: {flag_error(err, parser)}", file=sys.stderr)
        return 2
    except loop.Interrupted as stop:
        return stop.exit_code
    except (RunStopped, checkpoint.CheckpointError) as err:
        print(f"{parser.prog}: error: {err}", file=sys.stderr)
        return 3
    if rec:
        progress.show(
            f"done: {rec['iteration']} iterations, eval success {rec['eval_success']:.3f} "
            f"(final step {rec['eval_success_final']:.3f}) in {rec['wall_s']:.1f} s; run dir {cfg.run_dir}",
            ns.quiet,
        )
    return 0


if __name__ == "__main__":
    exit_with(run_main(main))
