"""Speed of the SPLID iteration on one device: SELECT verdicts per second, chunk time, compile
time, and the cost of vmapping seeds, each against a peer measured in the same run.

    python experiments/bench_splid.py --env push --num-envs 64,256,1024 --seeds 8 --out bench.json
    python experiments/bench_splid.py --env push --num-envs 1024,4096 --skip-chunk --train-iterations 10 \
        --lanes 0.25,0.5,1 --out select.json

Two verdict counts: *replayed* verdicts are the valid candidates (the object moved toward g'), each
decided by a replay; *pairs* are all (t, h) candidates with t + h <= T, the rest of which SELECT
rejects without a replay (g' is already achieved at s_t: the policy ties at zero steps).

Peers: SELECT on this machine's CPU cores through the same JAX code (``--cpu-peer``), and one seed
for the vmapped-seeds ratio. Medians over ``--repeats`` timed calls after one warm-up call; compile
time is the first call's time minus the median."""

from __future__ import annotations

import argparse
import dataclasses
import json
import statistics
import sys
import time

import jax
import jax.numpy as jnp

from splid_jax.config import TrainConfig
from splid_jax.learners.imitation.explore import draws, rollout
from splid_jax.learners.registry import make_algorithm
from splid_jax.learners.splid.select import num_lanes, select
from splid_jax.learners.splid.trainer import Trainer


def timed(fn, *args, repeats: int):
    """Timings of ``fn(*args)``, and its last output."""
    t0 = time.perf_counter()
    jax.block_until_ready(fn(*args))
    first = time.perf_counter() - t0
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = jax.block_until_ready(fn(*args))
        times.append(time.perf_counter() - t0)
    med = statistics.median(times)
    return {"median_s": med, "compile_s": max(first - med, 0.0), "runs": len(times)}, out


def trained_policy(env, cfg: TrainConfig, iterations: int):
    """The policy after ``iterations`` SPLID iterations: its exploration moves the object, so SELECT
    sees the share of valid candidates it sees in training (an untrained policy rarely moves it)."""
    trainer = Trainer(env, cfg)
    state, hyper, chunk = trainer.init(jax.random.PRNGKey(0)), trainer.hyper(), jax.jit(trainer.chunk)
    for _ in range(-(-iterations // cfg.eval_every)):  # whole chunks, at least one
        state, metrics = chunk(state, hyper)
    done = int(state.iteration)
    print(f"policy trained {done} iterations at N={cfg.num_envs}: eval success {metrics['eval_success']:.3f}")
    return state.policy


def bench_select(env, cfg: TrainConfig, device, repeats: int, pstate=None) -> dict:
    """Time SELECT alone on one batch explored by ``pstate`` (default: an untrained policy)."""
    trainer = Trainer(env, cfg)
    with jax.default_device(device):
        if pstate is None:
            pstate = trainer.init(jax.random.PRNGKey(0)).policy
        pstate = jax.device_put(pstate, device)
        sigma = jnp.float32(cfg.sigma)
        traj = jax.jit(lambda ps, k: rollout(env, trainer.policy, ps, *draws(env, k, cfg.num_envs), sigma))(
            pstate, jax.random.PRNGKey(1)
        )
        fn = jax.jit(
            lambda ps, tr: select(
                env,
                trainer.policy,
                ps,
                tr,
                cfg.horizon,
                jnp.int32(cfg.horizon),
                True,
                cfg.select_lanes,
            )
        )
        out, cands = timed(fn, pstate, traj, repeats=repeats)
    T, H, N = env.episode_length, cfg.horizon, cfg.num_envs
    pairs = N * sum(T - h + 1 for h in range(1, H + 1))  # (t, h) with t + h <= T
    verdicts, steps = int(cands.valid.sum()), int(cands.replay_steps)
    out.update(
        device=str(device),
        num_envs=N,
        select_lanes=cfg.select_lanes,
        lanes=num_lanes(T, N, cfg.select_lanes, H),
        pairs=pairs,
        verdicts=verdicts,
        replay_steps=steps,
        pairs_per_s=pairs / out["median_s"],
        verdicts_per_s=verdicts / out["median_s"],
        replay_steps_per_s=steps / out["median_s"],
        steps_per_verdict=steps / max(verdicts, 1),
    )
    return out


def bench_chunk(env, cfg: TrainConfig, seeds: int, repeats: int) -> dict:
    """Time whole compiled chunks (explore, SELECT, insert, BC, eval) for 1 seed and ``seeds`` seeds."""
    algo = make_algorithm(cfg, env)
    one, _ = timed(jax.jit(algo.chunk), algo.init(jax.random.PRNGKey(0)), algo.hyper(), repeats=repeats)
    keys = jnp.stack([jax.random.PRNGKey(s) for s in range(seeds)])
    states = jax.jit(jax.vmap(algo.init))(keys)
    hyper = jax.tree_util.tree_map(lambda x: jnp.broadcast_to(x, (seeds,)), algo.hyper())
    many, _ = timed(jax.jit(jax.vmap(algo.chunk)), states, hyper, repeats=repeats)
    return {
        "num_envs": cfg.num_envs,
        "iterations_per_chunk": cfg.eval_every,
        "one_seed": one,
        f"{seeds}_seeds": many,
        "seeds": seeds,
        "ratio_many_over_one": many["median_s"] / one["median_s"],
    }


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--env", default="push")
    p.add_argument("--num-envs", default="64,256,1024")
    p.add_argument("--horizon", type=int, default=8)
    p.add_argument("--seeds", type=int, default=8)
    p.add_argument("--eval-every", type=int, default=5)
    p.add_argument("--repeats", type=int, default=5)
    p.add_argument("--cpu-peer", type=int, default=0, help="num_envs for the SELECT peer on the CPU (0: skip)")
    p.add_argument("--skip-chunk", action="store_true")
    p.add_argument("--lanes", default=None, help="SELECT lane fractions to time, e.g. 0.25,0.5,1 (default: the task's)")
    p.add_argument("--env-options", default="", help="task fields as KEY=VALUE[,...], as in train")
    p.add_argument(
        "--train-iterations", type=int, default=0, help="train this many iterations first; SELECT uses that policy"
    )
    p.add_argument("--train-num-envs", type=int, default=512, help="num_envs of that training")
    p.add_argument("--out", default=None)
    a = p.parse_args()
    base = TrainConfig(
        env=a.env,
        horizon=a.horizon,
        eval_every=a.eval_every,
        iterations=a.eval_every,
        run_dir="/tmp/x",
        env_options=a.env_options,
    )
    env = base.make_env()
    dev = jax.devices()[0]
    res = {
        "env": a.env,
        "env_options": a.env_options,
        "command": " ".join(["python", *sys.argv]),
        "device": dev.device_kind,
        "platform": dev.platform,
        "jax": jax.__version__,
        "date": time.strftime("%Y-%m-%d"),
        "select": [],
        "chunk": [],
    }

    def save():  # after every measurement, so a run cut short by a time limit keeps what it measured
        if a.out:
            with open(a.out, "w") as fh:
                json.dump(res, fh, indent=2)

    pstate = None
    if a.train_iterations:
        pstate = trained_policy(env, dataclasses.replace(base, num_envs=a.train_num_envs), a.train_iterations)
        res["policy_trained_iterations"] = a.train_iterations
    lanes = [float(x) for x in a.lanes.split(",")] if a.lanes else [base.select_lanes]
    for n in [int(x) for x in a.num_envs.split(",")]:
        cfg = dataclasses.replace(base, num_envs=n)
        for frac in lanes:
            r = bench_select(env, dataclasses.replace(cfg, select_lanes=frac), dev, a.repeats, pstate)
            res["select"].append(r)
            save()
            print(f"SELECT {dev.platform} N={n} lanes {frac} ({r['lanes']}): {_select_line(r)}", flush=True)
        if not a.skip_chunk:
            c = bench_chunk(env, cfg, a.seeds, a.repeats)
            res["chunk"].append(c)
            save()
            print(
                f"CHUNK N={n}: 1 seed {c['one_seed']['median_s']:.3f}s (compile {c['one_seed']['compile_s']:.1f}s), "
                f"{a.seeds} seeds {c[f'{a.seeds}_seeds']['median_s']:.3f}s: ratio {c['ratio_many_over_one']:.2f}",
                flush=True,
            )
    if a.cpu_peer:
        cpu = jax.devices("cpu")[0]
        r = bench_select(env, dataclasses.replace(base, num_envs=a.cpu_peer), cpu, max(1, a.repeats // 2), pstate)
        res["select_cpu_peer"] = r
        save()
        print(f"SELECT cpu peer N={a.cpu_peer}: {_select_line(r)}", flush=True)


def _select_line(r: dict) -> str:
    return (
        f"{r['verdicts_per_s']:,.0f} replayed verdicts/s ({r['verdicts']} valid), {r['pairs_per_s']:,.0f} pairs/s, "
        f"{r['replay_steps_per_s']:,.0f} replay steps/s ({r['steps_per_verdict']:.2f} per verdict), "
        f"{r['median_s']:.3f}s, compile {r['compile_s']:.1f}s"
    )


if __name__ == "__main__":
    main()
