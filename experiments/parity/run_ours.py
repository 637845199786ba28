"""Run the scripted controllers in our MJX tasks (``envs.make(task)``) and record each episode.

All episodes of a task run vmapped under one jit (``lax.scan`` over the episode's steps); the records
match ``run_reference.py``: success at any step and at the final step, object start xy, goal xyz and
the achieved-goal displacement (final - initial). Works on CPU (slow) and GPU:

    python experiments/parity/run_ours.py --episodes 200 --out experiments/parity/results/ours.json
"""

from __future__ import annotations

import argparse
import contextlib
import datetime
import functools
import io
import json
import os
import platform
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))
sys.path.insert(1, str(Path(__file__).resolve().parent))

import jax  # noqa: E402
import jax.numpy as jnp  # noqa: E402
import numpy as np  # noqa: E402
from run_reference import parse_pairs  # noqa: E402  (its helpers need no reference packages)

TASKS = ("push", "slide", "pick_and_place", "reach")


def rollout_fn(env, controller, episodes: int):
    """A jitted ``key -> per-episode arrays`` running ``episodes`` scripted episodes in lock step (the
    achieved goal after every step too, for the strike-duration study, ``experiments/NOTES.md``)."""
    horizon = env.episode_length

    def one(key):
        s0 = env.reset(key)

        def body(state, _):
            obs = state.obs
            if obs.shape[-1] != 25:  # Reach: pad its 10 floats to the 25-float layout (grip first)
                obs = jnp.concatenate([obs[:3], jnp.zeros(22, obs.dtype)])
            nxt = env.step(state, controller(obs, state.desired_goal))
            return nxt, (nxt.success, nxt.invalid, nxt.achieved_goal)

        last, (succ, invalid, achieved) = jax.lax.scan(body, s0, None, length=horizon)
        return {
            "success_any": jnp.any(succ),
            "success_final": succ[-1],
            "invalid": jnp.any(invalid),
            "start": s0.achieved_goal,
            "goal": s0.desired_goal,
            "final": last.achieved_goal,
            "achieved": achieved,  # after each step
        }

    return jax.jit(lambda key: jax.vmap(one)(jax.random.split(key, episodes)))


def run_task(task: str, episodes: int, seed: int, overrides: dict | None = None,
             controller_kwargs: dict | None = None) -> dict:
    import envs
    from envs.fetch import scripted

    with contextlib.redirect_stdout(io.StringIO()):  # mujoco.mjx prints a warp notice on import
        env = envs.make(task, **(overrides or {}))
        fn = rollout_fn(env, functools.partial(scripted.CONTROLLERS[task], **(controller_kwargs or {})), episodes)
        key = jax.random.PRNGKey(seed)
        t0 = time.perf_counter()
        compiled = fn.lower(key).compile()
    compile_s = time.perf_counter() - t0
    t0 = time.perf_counter()
    out = jax.device_get(jax.block_until_ready(compiled(key)))
    run_s = time.perf_counter() - t0
    records = []
    for i in range(episodes):
        start, goal, final = (np.asarray(out[k][i], float) for k in ("start", "goal", "final"))
        records.append({
            "seed": i,
            "success_any": bool(out["success_any"][i]),
            "success_final": bool(out["success_final"][i]),
            "invalid": bool(out["invalid"][i]),
            "object_start": start.tolist(),
            "goal": goal.tolist(),
            "displacement": (final - start).tolist(),
            "final_distance": float(np.linalg.norm(final - goal)),
        })
    steps = episodes * env.episode_length
    return {
        "env": f"envs.make({task!r})",
        "compile_seconds": compile_s,
        "seconds": run_s,
        "env_steps_per_s": steps / run_s,
        "settings": {k: getattr(env, k) for k in ("timestep", "substeps", "iterations", "ls_iterations")
                     if hasattr(env, k)},
        "episodes": records,
    }


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--tasks", default=",".join(TASKS))
    p.add_argument("--episodes", type=int, default=200)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--out", default=str(ROOT / "experiments" / "parity" / "results" / "ours.json"))
    p.add_argument("--set", action="append", default=[], metavar="FIELD=VALUE",
                   help="task field override for every task, e.g. --set iterations=10 (repeatable)")
    p.add_argument("--controller", action="append", default=[], metavar="ARG=VALUE",
                   help="keyword argument of the scripted controllers, e.g. --controller aim_short=0.08 (repeatable)")
    args = p.parse_args(argv)
    overrides = parse_pairs(args.set)
    controller_kwargs = parse_pairs(args.controller)

    import mujoco

    dev = jax.devices()[0]
    device = (f"{dev.device_kind} ({dev.platform})" if dev.platform != "cpu"
              else f"CPU {platform.processor() or platform.machine()}, {os.cpu_count()} cores")
    out = {
        "side": "ours",
        "command": " ".join(["python", *sys.argv]),
        "date": datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%d"),
        "device": f"{device} (MJX)",
        "versions": {"jax": jax.__version__, "mujoco": mujoco.__version__},
        "episodes": args.episodes,
        "seed": args.seed,
        "overrides": overrides,
        "controller_kwargs": controller_kwargs,
        "tasks": {},
    }
    for task in args.tasks.split(","):
        res = run_task(task, args.episodes, args.seed, overrides, controller_kwargs)
        out["tasks"][task] = res
        recs = res["episodes"]
        sa = np.mean([r["success_any"] for r in recs])
        sf = np.mean([r["success_final"] for r in recs])
        bad = sum(r["invalid"] for r in recs)
        print(f"{task:15s} success any-step {sa:.3f} final-step {sf:.3f}  ({len(recs)} episodes; compile "
              f"{res['compile_seconds']:.0f} s, run {res['seconds']:.1f} s, {res['env_steps_per_s']:.0f} "
              f"env-steps/s{f', {bad} invalid' if bad else ''})", flush=True)
        Path(args.out).parent.mkdir(parents=True, exist_ok=True)
        Path(args.out).write_text(json.dumps(out, indent=1))  # after each task: partial results survive
    print("wrote", args.out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
