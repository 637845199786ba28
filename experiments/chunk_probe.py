"""Which stage of a cloning learner's next chunk does not finish: a run stalled on its device, probed from
its newest checkpoint.

A chunk is one compiled program, so a stalled one says nothing of where it stopped. This restores the run's
(or sweep's) newest checkpoint and replays the next chunk one member at a time, each stage its own jitted
program under a watchdog: exploration, SELECT over the explored candidates, the whole iteration (exploration,
SELECT, insert, cloning), and after the chunk's iterations the evaluation. The first stage still running after
``--limit`` seconds is named and the process exits 3 (a program stuck on a device cannot be cancelled). Each
member's program is the same computation as the chunk's, unbatched, so its floats may part from the sweep's
in the last bits.

    python experiments/chunk_probe.py runs/fig3/splid --limit 120 --members 0,3 --out probe.json
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import threading
import time
from pathlib import Path

import jax
import jax.numpy as jnp

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from splid_jax.common.evaluation import evaluate  # noqa: E402
from splid_jax.common.subgoals import steered  # noqa: E402
from splid_jax.config import TrainConfig  # noqa: E402
from splid_jax.learners.imitation.explore import draws, hold_fingers, rollout  # noqa: E402
from splid_jax.learners.registry import make_algorithm  # noqa: E402
from splid_jax.rollout import load_config  # noqa: E402
from splid_jax.runtime import checkpoint, loop  # noqa: E402
from splid_jax.runtime.run_files import SWEEP  # noqa: E402
from splid_jax.sweep import resume_configs  # noqa: E402


class Stalled(RuntimeError):
    """A stage outlasted the watchdog."""


def configs(run_dir: str) -> tuple[TrainConfig, list[TrainConfig] | None]:
    """The run's config and, for a sweep, its members'."""
    if os.path.isfile(os.path.join(run_dir, SWEEP)):
        return resume_configs(run_dir, {})
    return load_config(run_dir), None


def watched(name: str, limit: float, log: list[dict], fn, *args):
    """``fn(*args)`` to completion on its device, or ``Stalled`` once it has run ``limit`` seconds."""
    out: dict = {}

    def work():
        t0 = time.perf_counter()
        out["value"] = jax.block_until_ready(fn(*args))
        out["s"] = time.perf_counter() - t0

    thread = threading.Thread(target=work, daemon=True)
    thread.start()
    thread.join(limit)
    if thread.is_alive():
        log.append({"stage": name, "finished": False, "limit_s": limit})
        raise Stalled(f"{name} did not finish in {limit:g} s")
    log.append({"stage": name, "finished": True, "s": round(out["s"], 3)})
    print(f"{name}: {out['s']:.2f} s (compile included the first time)", flush=True)
    return out["value"]


def probe(run_dir: str, limit: float, members: list[int] | None, log: list[dict]) -> int:
    base, lanes = configs(run_dir)
    env = base.make_env()
    algo = make_algorithm(base, env)
    if not hasattr(algo, "select"):
        raise SystemExit(f"{run_dir}: a {base.algo} run; the probe replays the cloning learners' stages")
    stacked = lanes is not None
    keys = jnp.stack([jax.random.PRNGKey(m.seed) for m in lanes]) if stacked else jax.random.PRNGKey(base.seed)
    like = jax.eval_shape(jax.vmap(algo.init) if stacked else algo.init, keys)
    step, state, _ = checkpoint.restore(run_dir, like)
    print(f"{run_dir}: restored iteration {step}", flush=True)
    hypers = [loop._lane_hyper(algo, base, m) for m in lanes] if stacked else [algo.hyper(base)]

    def explore(ts, hyper):
        _, k_explore, _, _ = jax.random.split(ts.key, 4)  # as the iteration splits its key
        reset_keys, noise = draws(env, k_explore, base.num_envs)
        if env.moves_fingers:
            noise = hold_fingers(noise, hyper.gripper_hold)
        return rollout(env, algo.policy, ts.policy, reset_keys, noise, algo.sigma_at(ts.iteration, hyper),
                       hyper.explore_reach)  # fmt: skip

    run_explore = jax.jit(explore)
    run_select = jax.jit(lambda ts, hyper, traj: algo.select(ts.policy, traj, algo.horizon_at(ts.iteration, hyper)))
    run_iteration = jax.jit(algo.iteration)
    policy = steered(algo.policy, env, base.eval_subgoal_reach)
    run_eval = jax.jit(lambda ts: evaluate(env, policy, ts.policy, jax.random.split(ts.key)[1], base.eval_episodes))
    for i in members if members is not None else range(len(hypers)):
        ts = jax.tree.map(lambda x, i=i: x[i], state) if stacked else state
        for it in range(step + 1, step + base.eval_every + 1):
            where = f"member {i} iteration {it}"
            traj = watched(f"{where} exploration", limit, log, run_explore, ts, hypers[i])
            log[-1]["invalid_envs"] = int(jnp.sum(jnp.any(traj.invalid, axis=0)))
            cands = watched(f"{where} SELECT", limit, log, run_select, ts, hypers[i], traj)
            log[-1].update(pairs=int(cands.valid.sum()), accepted=int(cands.accept.sum()),
                           replay_steps=int(cands.replay_steps))  # fmt: skip
            ts, _ = watched(f"{where} whole", limit, log, run_iteration, ts, hypers[i])
        watched(f"member {i} evaluation", limit, log, run_eval, ts)
    print("every stage finished", flush=True)
    return 0


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("run_dir", help="a run or sweep directory with a checkpoint")
    p.add_argument("--limit", type=float, default=120.0, help="seconds a stage may run (default 120)")
    p.add_argument("--members", default=None, help="a sweep's member indices to probe, e.g. 0,3 (default: all)")
    p.add_argument("--out", type=Path, default=None, help="write every stage's outcome as JSON here")
    a = p.parse_args(argv)
    members = None if a.members is None else [int(x) for x in a.members.split(",")]
    log: list[dict] = []
    try:
        code = probe(a.run_dir, a.limit, members, log)
    except Stalled as err:
        print(f"stalled: {err}", flush=True)
        code = 3
    if a.out:
        a.out.write_text(json.dumps({"run_dir": a.run_dir, "stages": log}, indent=1))
    sys.stdout.flush()
    os._exit(code)  # a stalled stage's thread holds the device; it cannot be joined


if __name__ == "__main__":
    raise SystemExit(main())
