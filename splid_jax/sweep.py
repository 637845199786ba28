"""``python -m splid_jax.sweep``: seeds x sigma x H (x any other traced setting, ``--vary``) as ONE
compiled program.

Every member is a lane of ``jax.vmap`` over the chunk function (``splid_jax.runtime.loop``): seeds differ by
PRNG key, sigma, H and the ``--vary`` settings (a learner's ``sweeps`` in the registry: the noise's end,
Adam's rate, the acting average's decay) by the traced hyper-parameters (H masks candidates up to the
largest H of the grid), so a grid costs one compilation and runs in lock-step on the device. Each member writes its
own config.json and metrics.jsonl under RUN_DIR/<member>; the members' stacked state is checkpointed
under RUN_DIR, so ``--resume RUN_DIR`` continues a sweep as it continues a run."""

from __future__ import annotations

from splid_jax.cli import check_environment, exit_with, quiet_interrupts, run_main

if __name__ == "__main__":  # a signal while JAX loads ends the process with one line, no traceback
    quiet_interrupts()
    check_environment()

import dataclasses  # noqa: E402
import errno  # noqa: E402
import itertools  # noqa: E402
import json  # noqa: E402
import math  # noqa: E402
import os  # noqa: E402
import sys  # noqa: E402

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
from splid_jax.common.errors import InvalidConfig, check  # noqa: E402
from splid_jax.config import TrainConfig  # noqa: E402
from splid_jax.learners import registry  # noqa: E402
from splid_jax.presets import TUNED, TUNED_LEARNERS  # noqa: E402
from splid_jax.runtime import (  # noqa: E402
    checkpoint,
    loop,
    multihost,
    progress,
    run_files,  # noqa: E402
)
from splid_jax.runtime.loop import RunStopped  # noqa: E402
from splid_jax.tensorboard import recording  # noqa: E402


@dataclasses.dataclass(frozen=True)
class Member:
    seed: int
    sigma: float
    horizon: int
    settings: tuple[tuple[str, float | int], ...] = ()  # the --vary fields' values, in the order given

    @property
    def name(self) -> str:
        varied = "".join(f"-{field}{value:g}" for field, value in self.settings)
        return f"sigma{self.sigma:g}-H{self.horizon}{varied}-s{self.seed}"


def members(
    seeds: int,
    sigmas: tuple[float, ...],
    horizons: tuple[int, ...],
    base_seed: int = 0,
    varied: dict[str, tuple[float | int, ...]] | None = None,
) -> list[Member]:
    """Every combination of sigma, H and the ``varied`` fields' values, each on ``seeds`` seeds."""
    varied = varied or {}
    check(seeds >= 1, "seeds", seeds, "an integer >= 1")
    ok = len(sigmas) >= 1 and all(math.isfinite(s) and s >= 0 for s in sigmas)
    check(ok, "sigmas", sigmas, "one or more finite values >= 0")
    check(len(horizons) >= 1 and min(horizons) >= 1, "horizons", horizons, "one or more integers >= 1")
    for name, values in (("sigmas", sigmas), ("horizons", horizons), *varied.items()):  # one directory each
        check(len(set(values)) == len(values), name, ",".join(map(str, values)), "distinct values")
    points = itertools.product(sigmas, horizons, *varied.values(), range(seeds))
    return [Member(base_seed + p[-1], float(p[0]), int(p[1]), tuple(zip(varied, p[2:-1], strict=True))) for p in points]


def member_configs(cfg: TrainConfig, grid: list[Member]) -> tuple[TrainConfig, list[TrainConfig]]:
    """The sweep's config (shapes for the largest H; the largest value of each varied field, so an
    acting average is kept, and held pairs are told apart, when any member has one) and each member's,
    in RUN_DIR/<member>."""
    largest = {field: max(dict(m.settings)[field] for m in grid) for field, _ in grid[0].settings}
    base = dataclasses.replace(cfg, horizon=max(m.horizon for m in grid), **largest)
    lanes = [
        dataclasses.replace(
            base,
            seed=m.seed,
            sigma=m.sigma,
            horizon=m.horizon,
            run_dir=os.path.join(cfg.run_dir, m.name),
            **dict(m.settings),
        )
        for m in grid
    ]
    points = {(m.sigma, m.horizon, m.settings): lane for m, lane in zip(grid, lanes, strict=True)}
    for lane in points.values():  # each grid point's settings in their ranges, before any work
        lane.learner_config()
    return base, lanes


def grid_configs(
    given: dict,
    seeds: int,
    sigmas: tuple[float, ...],
    horizons: tuple[int, ...] | None,
    varied: dict[str, tuple[float | int, ...]] | None = None,
) -> tuple[TrainConfig, list[TrainConfig]]:
    """The sweep's and its members' configs from the explicit settings ``given``. Without ``horizons``
    the members take the task's own H and the horizon it falls to; a given H is kept throughout unless
    ``horizon_end`` is given too, as with ``train --horizon``."""
    task_h = None if horizons else TrainConfig(**given).horizon
    grid = members(seeds, sigmas, horizons or (task_h,), base_seed=given.get("seed", 0), varied=varied)
    # a varied setting counts as given, so the defaults that go with it resolve as with --FIELD (a given window
    # fixes Push's widening at 0 unless that is given too)
    fixed = {**given, **{k: max(v) for k, v in (varied or {}).items()}, "sigma": max(sigmas)}
    if horizons:  # shapes for the largest H, as a sweep's
        fixed["horizon"] = max(horizons)
    return member_configs(TrainConfig(**fixed), grid)


def run_sweep(cfg: TrainConfig, grid: list[Member], quiet: bool = False, resume: bool = False) -> list[dict]:
    """Train every member of ``grid`` in lock-step; returns each member's last metrics record."""
    base, lanes = member_configs(cfg, grid)
    env = base.make_env()
    base.check_env(env)
    return loop.run(base, env, members=lanes, resume=resume, quiet=quiet)


def _values(field: str, text: str, kind: type) -> tuple:
    words = [w.strip() for w in text.split(",")]
    try:
        return tuple(kind(w) for w in words)
    except ValueError:
        what = "integers" if kind is int else "numbers"
        raise InvalidConfig(field, text, f"comma-separated {what}, e.g. {'2,8' if kind is int else '0.5,1'}") from None


def build_parser() -> Parser:
    parser = Parser(
        prog="python -m splid_jax.sweep",
        description="Run a grid of seeds x sigma x H (x --vary settings) as one vmapped, compiled program; one "
        "metrics file per member.",
        epilog="Exit codes as train's: 0 done, 2 bad input (nothing written), 3 stopped, 130 Ctrl-C, 143 SIGTERM.",
    )
    # --sigmas and --horizons replace the single values
    add_config_flags(parser, TrainConfig, TUNED, exclude=frozenset({"sigma", "horizon"}), per_algo=TUNED_LEARNERS)
    add_learner_flags(parser)
    parser.add_argument("--seeds", type=int, default=None, help="seeds per grid point (default: 4)")
    parser.add_argument("--sigmas", default=None, help="comma-separated sigma values (default: 1.0)")
    parser.add_argument(
        "--horizons",
        default=None,
        help="comma-separated H values, each kept throughout unless --horizon-end is given (default: the task's H)",
    )
    parser.add_argument(
        "--vary",
        action="append",
        metavar="FIELD=V1,V2",
        help="one more traced setting to grid over, e.g. learning_rate=0.0005,0.001 (repeatable; the fields: "
        + ", ".join(f for f in _sweepable("splid"))
        + ")",
    )
    parser.add_argument("--resume", metavar="RUN_DIR", help="continue the sweep saved in RUN_DIR (its sweep.json)")
    parser.add_argument("--no-plot", action="store_true", help="skip the grid figure")
    parser.add_argument("--quiet", action="store_true", help="no progress display")
    parser.add_argument(
        "--tensorboard",
        metavar="DIR",
        help="also write every member's metrics as TensorBoard scalars under DIR/MEMBER, against episodes "
        '(needs pip install -e ".[tensorboard]")',
    )
    add_compile_cache_flag(parser)
    add_launch_flags(parser)
    return parser


TYPES = {f.name: str(f.type) for f in TrainConfig.settings_fields()}


def _sweepable(algo: str) -> tuple[str, ...]:
    """The traced settings ``--vary`` takes for ``algo``: those of its sweeps it reads, but sigma and H (their
    own flags)."""
    return tuple(f for f in registry.get(algo).sweeps if f not in ("sigma", "horizon") and registry.reads(algo, f))


def varied_values(items: list[str] | None, algo: str) -> dict[str, tuple[float | int, ...]]:
    """``--vary FIELD=V1,V2`` items as ``{field: values}``, each field one of ``algo``'s traced settings."""
    out: dict[str, tuple[float | int, ...]] = {}
    allowed = _sweepable(algo)
    for item in items or ():
        field, sep, text = (x.strip() for x in item.partition("="))
        if not sep or field not in allowed or field in out:
            fields = ", ".join(allowed) or f"none: --algo {algo} traces no setting but sigma and H"
            raise InvalidConfig("vary", item, f"FIELD=V1,V2 with FIELD one of {fields}, each field once")
        kind = int if TYPES[field] == "int" else float
        out[field] = _values(field, text, kind)
        check(all(map(math.isfinite, out[field])), field, text, "finite numbers")
    return out


def resume_configs(run_dir: str, given: dict) -> tuple[TrainConfig, list[TrainConfig]]:
    """The sweep's and its members' configs from RUN_DIR/sweep.json; only ``MAY_CHANGE_ON_RESUME``
    fields (iterations, checkpoint_every) may be given anew."""
    changed = [k for k in given if k not in run_files.MAY_CHANGE_ON_RESUME]
    if changed:
        raise InvalidConfig(changed[0], given[changed[0]], "as in the sweep being resumed (only iterations may change)")
    try:
        with open(os.path.join(run_dir, run_files.SWEEP)) as fh:
            saved = json.load(fh)
        base = TrainConfig.from_json({**saved["config"], **given, "run_dir": run_dir})
        lanes = [
            TrainConfig.from_json({**m, **given, "run_dir": os.path.join(run_dir, m["run_dir"])})
            for m in saved["members"]
        ]
    except (OSError, ValueError, KeyError, TypeError) as e:  # ValueError: not UTF-8, not JSON
        why = f" that can be read ({e.strerror})" if isinstance(e, OSError) and e.errno != errno.ENOENT else ""
        raise InvalidConfig("resume", run_dir, f"a sweep directory holding its {run_files.SWEEP}{why}") from None
    return base, lanes


def check_same_grid(
    lanes: list[TrainConfig],
    seeds: int | None,
    sigmas: str | None,
    horizons: str | None,
    varied: dict[str, tuple[float | int, ...]] | None = None,
) -> None:
    """A resumed sweep trains the grid it started with: a grid flag given anew must name that grid."""
    first = {"seeds": len({m.seed for m in lanes}), "sigmas": tuple(dict.fromkeys(m.sigma for m in lanes)),
             "horizons": tuple(dict.fromkeys(m.horizon for m in lanes))}  # fmt: skip
    given = {"seeds": seeds, "sigmas": None if sigmas is None else _values("sigmas", sigmas, float),
             "horizons": None if horizons is None else _values("horizons", horizons, int)}  # fmt: skip
    for field, values in (varied or {}).items():
        first[field], given[field] = tuple(dict.fromkeys(getattr(m, field) for m in lanes)), values
    for name, value in given.items():
        if value is not None and value != first[name]:
            shown = ",".join(map(str, first[name])) if isinstance(first[name], tuple) else first[name]
            raise InvalidConfig(name, value, f"{shown} as in the sweep being resumed (only iterations may change)")


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    ns = parser.parse_args(argv)
    use_compile_cache(ns.compile_cache)
    try:
        start_processes(ns)
        given = explicit_values(TrainConfig, ns)
        if ns.resume:  # its sweep.json: process 0's
            cfg, lanes = multihost.from_first(lambda: resume_configs(ns.resume, given))
            check_same_grid(lanes, ns.seeds, ns.sigmas, ns.horizons, varied_values(ns.vary, cfg.algo))
        else:
            algo = given.get("algo", "splid")
            refuse_unread(given, algo, ns)
            for name, field in (("sigmas", "sigma"), ("horizons", "horizon")):
                check(getattr(ns, name) is None or registry.reads(algo, field), name, getattr(ns, name),
                      f"unset with --algo {algo}, which does not read {field}")  # fmt: skip
            given.setdefault("run_dir", os.path.join("runs", f"sweep-{given.get('env', 'point')}"))
            sigmas = _values("sigmas", "1.0" if ns.sigmas is None else ns.sigmas, float)
            horizons = None if ns.horizons is None else _values("horizons", ns.horizons, int)
            seeds = 4 if ns.seeds is None else ns.seeds
            varied = varied_values(ns.vary, algo)
            for field in varied.keys() & given.keys():
                raise InvalidConfig(field, given[field], f"given once: either --{field.replace('_', '-')} or --vary")
            cfg, lanes = grid_configs(given, seeds, sigmas, horizons, varied)
        env = cfg.make_env()
        cfg.check_env(env)
        with recording(ns.tensorboard, per_member=True) as on_record:
            loop.run(cfg, env, members=lanes, resume=bool(ns.resume), quiet=ns.quiet, on_record=on_record)
        interrupts_now(f"after the sweep completed ({cfg.run_dir} is whole; --resume {cfg.run_dir} draws its figure)")
    except InvalidConfig as err:
        print(f"{parser.prog}: error: {flag_error(err, parser)}", file=sys.stderr)
        return 2
    except loop.Interrupted as stop:
        return stop.exit_code
    except (RunStopped, checkpoint.CheckpointError) as err:
        print(f"{parser.prog}: error: {err}", file=sys.stderr)
        return 3
    if not ns.no_plot and multihost.is_first():
        from splid_jax import plot  # matplotlib only where a figure is drawn: a --no-plot process starts sooner

        out = os.path.join(cfg.run_dir, "grid.png")
        plot.main([m.run_dir for m in lanes] + ["--group", "--out", out, "--overwrite"])  # its own, redrawn
        progress.show(f"figure: {out}", ns.quiet)
    return 0


if __name__ == "__main__":
    exit_with(run_main(main))
