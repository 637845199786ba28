"""``python -m splid_jax.sweep``: seeds x sigma x H as ONE compiled program.

Every member is a lane of ``jax.vmap`` over the chunk function: seeds differ by PRNG key, sigma and
H by the traced ``Hyper`` (H masks candidates up to the largest H of the grid), so a grid costs
one compilation and runs in lock-step on the device."""

from __future__ import annotations

import argparse
import dataclasses
import itertools
import json
import os
import sys
import time

import jax
import jax.numpy as jnp

from envs.base import InvalidConfig, check
from splid_jax import plot, progress
from splid_jax.cli import add_compile_cache_flag, add_config_flags, explicit_values, use_compile_cache
from splid_jax.config import TASK_DEFAULTS, TrainConfig
from splid_jax.train import make_env, pop_select_steps
from splid_jax.trainer import Hyper, Trainer


@dataclasses.dataclass(frozen=True)
class Member:
    seed: int
    sigma: float
    horizon: int

    @property
    def name(self) -> str:
        return f"sigma{self.sigma:g}-H{self.horizon}-s{self.seed}"


def members(seeds: int, sigmas: tuple[float, ...], horizons: tuple[int, ...], base_seed: int = 0) -> list[Member]:
    check(seeds >= 1, "seeds", seeds, "an integer >= 1")
    check(len(sigmas) >= 1 and min(sigmas) >= 0, "sigmas", sigmas, "one or more values >= 0")
    check(len(horizons) >= 1 and min(horizons) >= 1, "horizons", horizons, "one or more integers >= 1")
    return [Member(base_seed + s, float(sg), int(h)) for sg, h, s in itertools.product(sigmas, horizons, range(seeds))]


def run_sweep(cfg: TrainConfig, grid: list[Member], quiet: bool = False) -> list[dict]:
    """Train every member of ``grid`` in lock-step; returns each member's last metrics record."""
    env = make_env(cfg.env, **cfg.env_overrides())
    max_h = max(m.horizon for m in grid)
    trainer = Trainer(env, dataclasses.replace(cfg, horizon=max_h))
    keys = jnp.stack([jax.random.PRNGKey(m.seed) for m in grid])
    hyper = Hyper(
        sigma=jnp.asarray([m.sigma for m in grid], jnp.float32),
        horizon=jnp.asarray([m.horizon for m in grid], jnp.int32),
    )
    state = jax.jit(jax.vmap(trainer.init))(keys)
    chunk = jax.jit(jax.vmap(trainer.chunk))
    dirs = [os.path.join(cfg.run_dir, m.name) for m in grid]
    for d, m in zip(dirs, grid, strict=True):
        os.makedirs(d, exist_ok=True)
        with open(os.path.join(d, "config.json"), "w") as fh:
            json.dump({**cfg.to_json(), "seed": m.seed, "sigma": m.sigma, "horizon": m.horizon, "run_dir": d}, fh)
        open(os.path.join(d, "metrics.jsonl"), "w").close()
    progress.show(f"sweep: {len(grid)} members of {cfg.env} in one program, {cfg.iterations} iterations", quiet)
    start, iteration, last = time.perf_counter(), 0, []
    totals = [0] * len(grid)  # SELECT replay steps per member, exact Python ints
    while iteration < cfg.iterations:
        t0 = time.perf_counter()
        state, metrics = chunk(state, hyper)
        metrics = jax.device_get(metrics)
        chunk_s, iteration = time.perf_counter() - t0, iteration + cfg.eval_every
        wall = time.perf_counter() - start
        last = []
        per_member = pop_select_steps(metrics)
        for i, d in enumerate(dirs):
            totals[i] += int(per_member[i])
            rec = trainer.counters(iteration, totals[i])
            rec.update({k: v[i].item() for k, v in metrics.items() if k != "finite"})
            rec.update(finite=bool(metrics["finite"][i]), wall_s=wall, chunk_s=chunk_s)
            with open(os.path.join(d, "metrics.jsonl"), "a") as fh:
                fh.write(json.dumps(rec) + "\n")
            last.append(rec)
        best = max(last, key=lambda r: r["eval_success"])
        progress.show(
            f"iter {iteration:>5}/{cfg.iterations}  mean success {sum(r['eval_success'] for r in last) / len(last):.3f}"
            f"  best {best['eval_success']:.3f}  chunk {chunk_s:.1f}s  wall {wall:.1f}s",
            quiet,
        )
    return last


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m splid_jax.sweep",
        description="Run a grid of seeds x sigma x H as one vmapped, compiled program; one metrics file per member.",
    )
    # --sigmas and --horizons replace the single values (--sigma and --horizon abbreviate them);
    # a sweep keeps no checkpoints
    add_config_flags(parser, TrainConfig, TASK_DEFAULTS, exclude=frozenset({"sigma", "horizon", "checkpoint_every"}))
    parser.add_argument("--seeds", type=int, default=4, help="seeds per grid point (default: 4)")
    parser.add_argument("--sigmas", default="1.0", help="comma-separated sigma values (default: 1.0)")
    parser.add_argument("--horizons", default="8", help="comma-separated H values (default: 8)")
    parser.add_argument("--no-plot", action="store_true", help="skip the grid figure")
    parser.add_argument("--quiet", action="store_true", help="no progress display")
    add_compile_cache_flag(parser)
    ns = parser.parse_args(argv)
    use_compile_cache(ns.compile_cache)
    try:
        given = explicit_values(TrainConfig, ns)
        given.setdefault("run_dir", os.path.join("runs", f"sweep-{given.get('env', 'point')}"))
        sigmas = tuple(float(x) for x in ns.sigmas.split(","))
        horizons = tuple(int(x) for x in ns.horizons.split(","))
        grid = members(ns.seeds, sigmas, horizons, base_seed=given.get("seed", 0))
        cfg = TrainConfig(**{**given, "horizon": max(horizons), "sigma": max(sigmas)})
        cfg.check_env(make_env(cfg.env, **cfg.env_overrides()))
    except (InvalidConfig, ValueError) as err:
        print(f"{parser.prog}: error: {err}", file=sys.stderr)
        return 2
    run_sweep(cfg, grid, ns.quiet)
    if not ns.no_plot:
        out = os.path.join(cfg.run_dir, "grid.png")
        plot.main([os.path.join(cfg.run_dir, m.name) for m in grid] + ["--group", "--out", out])
        progress.show(f"figure: {out}", ns.quiet)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
