"""``python -m splid_jax.train --env ENV``: train SPLID, log, checkpoint, resume.

Python runs only between compiled chunks: it logs, writes metrics.jsonl and saves checkpoints."""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import os
import signal
import sys
import threading
import time

import jax
import numpy as np

import envs
from envs.base import InvalidConfig
from splid_jax import checkpoint, progress
from splid_jax.cli import add_compile_cache_flag, add_config_flags, explicit_values, use_compile_cache
from splid_jax.config import TASK_DEFAULTS, TrainConfig, saved_fields
from splid_jax.trainer import Trainer

# Fields a resumed run must share with its checkpoint; the rest may change on resume.
_MAY_CHANGE_ON_RESUME = {"iterations", "run_dir", "checkpoint_every"}


class RunStopped(RuntimeError):
    """The run stopped early for a reason the user must see (NaN); exit code 3."""


def make_env(name: str, **overrides) -> envs.GoalEnv:
    with contextlib.redirect_stdout(io.StringIO()):  # MJX prints a warp notice on import
        return envs.make(name, **overrides)


def _identity(cfg: TrainConfig) -> dict:
    """The settings a checkpoint must share with the run resuming it, as JSON stores them."""
    ident = {k: v for k, v in cfg.to_json().items() if k not in _MAY_CHANGE_ON_RESUME}
    if not ident["env_options"]:  # absent from runs saved before the field existed; "" means the same
        del ident["env_options"]
    return json.loads(json.dumps(ident))


def env_settings(env: envs.GoalEnv) -> dict:
    """The task's every option as JSON stores it: a resume under other task defaults fails naming one."""
    return json.loads(json.dumps(env.settings()))


def pop_select_steps(metrics: dict) -> np.ndarray:
    """Pops a chunk's per-iteration SELECT replay steps ([..., eval_every], int32 on the device) and
    sums them over the iterations in int64 (per member of a sweep, where there is a member axis)."""
    return np.asarray(metrics.pop("select_steps"), np.int64).sum(axis=-1)


def _record(
    trainer: Trainer, metrics: dict, wall_s: float, chunk_s: float, iteration: int, total: int, chunk_steps: int
) -> dict:
    """One metrics line; ``total`` SELECT replay steps in the run so far, ``chunk_steps`` in this chunk."""
    rec = trainer.counters(iteration, total)
    for k, v in metrics.items():
        rec[k] = v.item()
    chunk = trainer.counters(trainer.cfg.eval_every, chunk_steps)
    steps = chunk["env_steps"] + chunk["select_steps"]
    rec["buffer_fill"] = rec["buffer_size"] / trainer.cfg.buffer_size
    rec["steps_per_s"] = steps / max(chunk_s, 1e-9)
    rec["wall_s"] = wall_s
    return rec


def run(cfg: TrainConfig, env: envs.GoalEnv | None = None, resume: bool = False, quiet: bool = False) -> dict:
    """Train to ``cfg.iterations``; returns the last metrics record. Resumes from the newest
    checkpoint in ``cfg.run_dir`` when ``resume``."""
    env = env or make_env(cfg.env, **cfg.env_overrides())
    trainer = Trainer(env, cfg)
    chunk = jax.jit(trainer.chunk)
    os.makedirs(cfg.run_dir, exist_ok=True)
    metrics_path = os.path.join(cfg.run_dir, "metrics.jsonl")
    state = trainer.init(jax.random.PRNGKey(cfg.seed))
    wall_before, select_steps = 0.0, 0
    if resume:
        # the meta check comes first, so a changed setting is named rather than a leaf's shape
        step, state, meta = checkpoint.restore(cfg.run_dir, state, expect_meta={"config": _identity(cfg)},
                                               expect_meta_if_saved={"env": env_settings(env)})
        wall_before = float(meta["wall_s"])
        kept = [r for r in _read_jsonl(metrics_path) if r["iteration"] <= step]
        select_steps = int(meta["select_steps"])
        _write_jsonl(metrics_path, kept)
        progress.show(f"resumed {cfg.run_dir} at iteration {step}", quiet)
    else:
        open(metrics_path, "w").close()
    with open(os.path.join(cfg.run_dir, "config.json"), "w") as fh:
        json.dump(cfg.to_json(), fh, indent=2)

    hyper = trainer.hyper()
    iteration = int(state.iteration)
    progress.show(f"splid_jax: env={cfg.env} select={cfg.select} device={jax.devices()[0].platform}", quiet)
    progress.show(progress.HEADER, quiet)
    start = time.perf_counter()
    rec, chunks_done = {}, 0

    def save(st, it, total):
        meta = {"config": _identity(cfg), "env": env_settings(env),
                "wall_s": wall_before + time.perf_counter() - start, "select_steps": total}
        with _interrupt_after():
            checkpoint.save(cfg.run_dir, it, st, meta)

    try:
        while iteration < cfg.iterations:
            t0 = time.perf_counter()
            new_state, metrics = chunk(state, hyper)
            metrics = jax.device_get(metrics)
            chunk_s = time.perf_counter() - t0
            if not bool(metrics.pop("finite")):
                raise RunStopped(
                    f"non-finite loss or parameters after iteration {iteration + cfg.eval_every}; "
                    f"stopped, the last good checkpoint (iteration {iteration}) is kept in {cfg.run_dir}"
                )
            done = iteration + cfg.eval_every
            chunk_steps = int(pop_select_steps(metrics))
            new_total = select_steps + chunk_steps
            rec = _record(
                trainer, metrics, wall_before + time.perf_counter() - start, chunk_s, done, new_total, chunk_steps
            )
            with open(metrics_path, "a") as fh:  # a line past the checkpoint is dropped on resume
                fh.write(json.dumps(rec) + "\n")
            state, iteration, chunks_done, select_steps = new_state, done, chunks_done + 1, new_total
            progress.show(progress.line(rec, cfg.iterations), quiet)
            if iteration == cfg.iterations or (cfg.checkpoint_every and chunks_done % cfg.checkpoint_every == 0):
                save(state, iteration, select_steps)
    except KeyboardInterrupt:
        if checkpoint.latest_step(cfg.run_dir) != iteration:
            save(state, iteration, select_steps)
        progress.show(f"interrupted: saved iteration {iteration} to {cfg.run_dir}; resume with --resume", quiet)
        raise
    except RunStopped:
        if checkpoint.latest_step(cfg.run_dir) != iteration:
            save(state, iteration, select_steps)
        raise
    return rec


@contextlib.contextmanager
def _interrupt_after():
    """Holds a Ctrl-C that comes during the block until the block is done: an interrupted orbax save
    leaves a temporary directory that the save on the way out cannot replace."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    caught = []
    previous = signal.signal(signal.SIGINT, lambda *_: caught.append(True))
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
    if caught:
        raise KeyboardInterrupt


def _read_jsonl(path: str) -> list[dict]:
    if not os.path.exists(path):
        return []
    with open(path) as fh:
        return [json.loads(line) for line in fh if line.strip()]


def _write_jsonl(path: str, records: list[dict]) -> None:
    with open(path, "w") as fh:
        fh.writelines(json.dumps(r) + "\n" for r in records)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="python -m splid_jax.train",
        description="Train SPLID (explore, SELECT by first hit time, behaviour cloning) on a goal-conditioned task.",
    )
    add_config_flags(parser, TrainConfig, TASK_DEFAULTS)
    parser.add_argument("--resume", metavar="RUN_DIR", help="continue the run saved in RUN_DIR (its config.json)")
    parser.add_argument("--quiet", action="store_true", help="no progress display")
    add_compile_cache_flag(parser)
    return parser


def config_from_cli(ns: argparse.Namespace) -> tuple[TrainConfig, bool]:
    given = explicit_values(TrainConfig, ns)
    if ns.resume is None:
        cfg = TrainConfig(**given)
        if os.path.isdir(cfg.run_dir) and checkpoint.latest_step(cfg.run_dir) is not None:
            raise InvalidConfig("run_dir", cfg.run_dir, "a directory without a run in it (or pass --resume RUN_DIR)")
        return cfg, False
    path = os.path.join(ns.resume, "config.json")
    if not os.path.isfile(path):
        raise InvalidConfig("resume", ns.resume, "a run directory holding config.json")
    with open(path) as fh:
        saved = saved_fields(json.load(fh))
    for k, v in given.items():
        if k not in _MAY_CHANGE_ON_RESUME and v != saved.get(k) and not (isinstance(v, tuple) and list(v) == saved[k]):
            raise InvalidConfig(k, v, f"{saved.get(k)!r} as in the run being resumed (only iterations may change)")
    saved.update(given, run_dir=ns.resume)
    return TrainConfig(**saved), True


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    ns = parser.parse_args(argv)
    use_compile_cache(ns.compile_cache)
    try:
        cfg, resume = config_from_cli(ns)
        env = make_env(cfg.env, **cfg.env_overrides())
        cfg.check_env(env)
        if resume and checkpoint.latest_step(cfg.run_dir) is None:
            raise InvalidConfig("resume", cfg.run_dir, "a run directory holding a checkpoint")
    except InvalidConfig as err:
        print(f"{parser.prog}: error: {err}", file=sys.stderr)
        return 2
    try:
        rec = run(cfg, env, resume=resume, quiet=ns.quiet)
    except KeyboardInterrupt:
        return 130
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
    np.set_printoptions(precision=4)
    raise SystemExit(main())
