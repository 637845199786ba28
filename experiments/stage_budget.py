"""Time budget per stage of a SPLID iteration and a HER cycle, at a task's default sizes.

Each stage runs as its own jitted program on the state a short training left (so SELECT and HER's
updates see realistic work): the medians of ``--repeats`` calls after a warm-up, with
``block_until_ready``; compile time is the first call's time minus the median. The whole chunk
(``eval_every`` iterations and one evaluation, the program training runs) is timed the same way,
so the stages' sum can be held against it.

    python experiments/stage_budget.py --env push --algos splid her --out budget.json

``XLA_FLAGS`` is read as usual, so flag variants are measured by running the script once per
variant (``--label`` names the variant in the output)."""

from __future__ import annotations

import argparse
import json
import os
import sys
import time

import jax
import jax.numpy as jnp
from bench_splid import timed  # this folder's scripts share their timer

from splid_jax.common.errors import InvalidConfig
from splid_jax.common.evaluation import evaluate
from splid_jax.config import TrainConfig
from splid_jax.figures.settings import parse_sets
from splid_jax.learners.imitation import relabel_buffer
from splid_jax.learners.imitation.explore import draws, rollout
from splid_jax.learners.registry import make_algorithm
from splid_jax.runtime import loop, programs
from splid_jax.runtime.signals import Signals


def chunk_row(algo, state, hyper, cfg: TrainConfig, chunk_repeats: int, warm_chunks: int):
    """The whole chunk's timing row, after ``warm_chunks`` (>= 1) trained chunks (the first one's time,
    compilation included, less the median is the compile time), and the state they left. The chunk is
    compiled and run as the host loop does (``runtime.programs``: training and report side by side)."""
    sharding = jax.sharding.SingleDeviceSharding(jax.devices()[0])
    state, hyper = loop.canonical((state, hyper), sharding)
    like = loop.abstract((state, hyper), sharding)
    t0 = time.perf_counter()
    chunk = programs.compile_all(programs.trace(programs.parts(algo, stacked=False), *like), Signals())
    state, _ = jax.block_until_ready(chunk(state, hyper))
    first_s = time.perf_counter() - t0
    for _ in range(warm_chunks - 1):
        state, _ = jax.block_until_ready(chunk(state, hyper))
    row, _ = timed(chunk, state, hyper, repeats=chunk_repeats)
    row["compile_s"] = max(first_s - row["median_s"], 0.0)
    row["iterations"] = cfg.eval_every
    return row, state


def shown(cfg: TrainConfig, *keys: str) -> dict:
    return {k: cfg.to_json()[k] for k in ("env", "env_options", "num_envs", *keys, "eval_every")}


def splid_budget(env_name: str, env_options: str, repeats: int, chunk_repeats: int, warm_chunks: int,
                 chunk_only: bool = False, settings: dict | None = None) -> dict:  # fmt: skip
    cfg = TrainConfig(env=env_name, env_options=env_options, run_dir="/tmp/stage-budget", **(settings or {}))
    env = cfg.make_env()
    algo = make_algorithm(cfg, env)
    hyper = algo.hyper()
    state = algo.init(jax.random.PRNGKey(0))
    # trained first, so the policy moves the object and SELECT sees real work
    rows = {}
    rows["chunk"], state = chunk_row(algo, state, hyper, cfg, chunk_repeats, warm_chunks)
    if chunk_only:
        return {"config": shown(cfg, "bc_steps", "select_lanes", *(settings or {})), "stages": rows}
    pstate, key = state.policy, jax.random.PRNGKey(1)
    sigma, horizon = hyper.sigma, hyper.horizon

    def explore_fn(pstate, key):
        keys, noise = draws(env, key, cfg.num_envs)
        return rollout(env, algo.policy, pstate, keys, noise, sigma)

    rows["explore"], traj = timed(jax.jit(explore_fn), pstate, key, repeats=repeats)

    def select_fn(pstate, traj):
        return algo.select(pstate, traj, horizon)

    rows["select"], cands = timed(jax.jit(select_fn), pstate, traj, repeats=repeats)
    rows["select"]["replay_steps"] = int(cands.replay_steps)
    rows["select"]["valid"] = int(jnp.sum(cands.valid))

    def insert_fn(buf, cands):
        return relabel_buffer.insert(buf, cands.obs, cands.goal, cands.action, cands.accept)

    rows["insert"], buf = timed(jax.jit(insert_fn), state.buffer, cands, repeats=repeats)

    def bc_fn(pstate, opt_state, online, buf, key):
        return algo.clone(pstate, opt_state, online, buf, key, hyper)

    rows["bc"], _ = timed(jax.jit(bc_fn), pstate, state.opt_state, state.online, buf, key, repeats=repeats)
    rows["bc"]["steps"] = cfg.bc_steps

    def eval_fn(pstate, key):
        return evaluate(env, algo.policy, pstate, key, cfg.eval_episodes)

    rows["evaluate"], _ = timed(jax.jit(eval_fn), pstate, key, repeats=repeats)
    rows["evaluate"]["episodes"] = cfg.eval_episodes
    return {"config": shown(cfg, "bc_steps"), "stages": rows}


def her_budget(env_name: str, env_options: str, repeats: int, chunk_repeats: int, warm_chunks: int,
               chunk_only: bool = False, her_options: str = "", num_envs: int | None = None) -> dict:  # fmt: skip
    cfg = TrainConfig(env=env_name, env_options=env_options, algo="her", run_dir="/tmp/stage-budget-her",
                      her_options=her_options, num_envs=num_envs)  # fmt: skip
    env = cfg.make_env()
    algo = make_algorithm(cfg, env)
    state = algo.init(jax.random.PRNGKey(0))
    rows = {}
    rows["chunk"], state = chunk_row(algo, state, {}, cfg, chunk_repeats, warm_chunks)
    if chunk_only:
        return {"config": shown(cfg), "stages": rows}
    key = jax.random.PRNGKey(1)
    rows["explore"], (episodes, valid, _) = timed(jax.jit(algo.explore), state.policy, key, repeats=repeats)

    def store_fn(hs, episodes, valid, key):
        from splid_jax.learners.her.episode_buffer import buffer_insert

        return hs.replace(
            buffer=buffer_insert(hs.buffer, episodes, valid),
            policy=algo.update_normaliser(hs.policy, episodes, valid, key),
        )

    rows["store_and_normalise"], state = timed(jax.jit(store_fn), state, episodes, valid, key, repeats=repeats)

    rows["updates"], _ = timed(jax.jit(algo.updates), state, key, repeats=repeats)
    rows["updates"]["steps"] = algo.n_updates

    def eval_fn(pstate, key):
        return evaluate(env, algo.policy, pstate, key, cfg.eval_episodes)

    rows["evaluate"], _ = timed(jax.jit(eval_fn), state.policy, key, repeats=repeats)
    rows["evaluate"]["episodes"] = cfg.eval_episodes
    return {"config": shown(cfg), "stages": rows}


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0], allow_abbrev=False)
    p.add_argument("--env", default="push")
    p.add_argument("--env-options", default="", help="task fields as KEY=VALUE[,KEY=VALUE...]")
    p.add_argument("--algos", nargs="+", default=["splid", "her"], choices=["splid", "her"])
    p.add_argument("--repeats", type=int, default=5)
    p.add_argument("--chunk-repeats", type=int, default=3, help="timed calls of the whole chunk")
    p.add_argument("--warm-chunks", type=int, default=1, help="chunks trained before timing (>= 1)")
    p.add_argument("--chunk-only", action="store_true", help="time the whole chunk alone, not each stage")
    p.add_argument("--label", default="default", help="the variant's name (e.g. its XLA flags)")
    p.add_argument(
        "--set", action="append", default=[], help="a SPLID setting as FIELD=VALUE, e.g. select_lanes=2; repeatable"
    )
    p.add_argument("--her-options", default="", help="HER's settings as KEY=VALUE[,KEY=VALUE...]")
    p.add_argument("--her-num-envs", type=int, default=None, help="HER's episodes per cycle (default: the task's)")
    p.add_argument("--out", required=True)
    args = p.parse_args()
    try:  # a wrong setting fails here, naming it, before any compile
        settings = parse_sets(args.set, methods=())[None]
        TrainConfig(env=args.env, env_options=args.env_options, run_dir="/tmp/stage-budget", **settings)
    except InvalidConfig as e:
        p.error(str(e))
    result = {
        "label": args.label,
        "xla_flags": os.environ.get("XLA_FLAGS", ""),
        "device": jax.devices()[0].device_kind,
        "jax": jax.__version__,
        "date": time.strftime("%Y-%m-%d"),
        "command": " ".join(sys.argv),
    }
    budgets = {"splid": splid_budget, "her": her_budget}
    for name in args.algos:
        sizes = (args.repeats, args.chunk_repeats, max(1, args.warm_chunks))
        extra = {"settings": settings} if name == "splid" else {"her_options": args.her_options}
        if name == "her":
            extra["num_envs"] = args.her_num_envs
        result[name] = budgets[name](args.env, args.env_options, *sizes, chunk_only=args.chunk_only, **extra)
        with open(args.out, "w") as fh:  # after each learner, so a cut call keeps what it measured
            json.dump(result, fh, indent=2)
        for stage, row in result[name]["stages"].items():
            print(f"{args.label} {name} {stage}: {row['median_s'] * 1e3:.1f} ms (compile {row['compile_s']:.1f} s)")


if __name__ == "__main__":
    main()
