"""Run the scripted controllers in Gymnasium-Robotics ``Fetch*-v4`` (MuJoCo C) and record each episode.

Run it with the reference environment made by ``setup_reference.sh``:

    experiments/parity/.venv-ref/bin/python experiments/parity/run_reference.py \
        --episodes 200 --out experiments/parity/results/reference.json

Per episode it records: success at any step and at the final step, object start xy, goal xyz and the
achieved-goal displacement (final - initial). ``--bench-steps`` also measures env-steps/s under random
actions on one process and on ``--procs`` processes (default: all cores).
"""

from __future__ import annotations

import argparse
import datetime
import importlib.util
import json
import multiprocessing as mp
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
TASKS = {
    "reach": "FetchReach-v4",
    "push": "FetchPush-v4",
    "slide": "FetchSlide-v4",
    "pick_and_place": "FetchPickAndPlace-v4",
}


def load_scripted():
    """Import ``envs/fetch/scripted.py`` by path: it needs only jax.numpy, not the rest of ``envs``."""
    spec = importlib.util.spec_from_file_location("scripted", ROOT / "envs" / "fetch" / "scripted.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def make_env(env_id: str):
    import gymnasium as gym
    import gymnasium_robotics

    gym.register_envs(gymnasium_robotics)
    return gym.make(env_id)


def full_obs(obs: dict) -> np.ndarray:
    """The reference observation, with Reach's 10 floats padded to the 25-float layout (grip first)."""
    o = obs["observation"]
    return o if o.shape[0] == 25 else np.concatenate([o[:3], np.zeros(22, o.dtype)])


def run_episodes(task: str, episodes: int, seed: int, controller_kwargs: dict | None = None) -> list[dict]:
    import jax

    scripted = load_scripted()
    fn = scripted.CONTROLLERS[task]
    policy = jax.jit(lambda o, g: fn(o, g, **(controller_kwargs or {})))
    env = make_env(TASKS[task])
    records = []
    for ep in range(episodes):
        obs, _ = env.reset(seed=seed + ep)
        start = obs["achieved_goal"].copy()
        goal = obs["desired_goal"].copy()
        any_success = False
        steps = env.spec.max_episode_steps
        for _ in range(steps):
            action = np.asarray(policy(full_obs(obs), obs["desired_goal"]), dtype=np.float64)
            obs, _, _, _, info = env.step(action)
            any_success |= bool(info["is_success"])
        records.append({
            "seed": seed + ep,
            "success_any": any_success,
            "success_final": bool(info["is_success"]),
            "object_start": start.tolist(),
            "goal": goal.tolist(),
            "displacement": (obs["achieved_goal"] - start).tolist(),
            "final_distance": float(np.linalg.norm(obs["achieved_goal"] - goal)),
        })
    env.close()
    return records


def _bench_worker(args):
    env_id, steps, seed = args
    env = make_env(env_id)
    env.reset(seed=seed)
    env.action_space.seed(seed)
    t0 = time.perf_counter()
    for _ in range(steps):
        _, _, term, trunc, _ = env.step(env.action_space.sample())
        if term or trunc:
            env.reset()
    return steps, time.perf_counter() - t0


def bench(env_id: str, steps: int, procs: int) -> dict:
    n, secs = _bench_worker((env_id, steps, 0))
    single = n / secs
    with mp.get_context("spawn").Pool(procs) as pool:
        t0 = time.perf_counter()
        results = pool.map(_bench_worker, [(env_id, steps, i) for i in range(procs)])
        wall = time.perf_counter() - t0
    total = sum(r[0] for r in results)
    return {
        "env": env_id,
        "steps_per_proc": steps,
        "single_process_steps_per_s": single,
        "procs": procs,
        # Sum of each worker's own rate (excludes pool start-up) and the end-to-end rate including it.
        "multi_process_steps_per_s": sum(r[0] / r[1] for r in results),
        "multi_process_wall_steps_per_s": total / wall,
        "speedup": sum(r[0] / r[1] for r in results) / single,
    }


def parse_pairs(items) -> dict:
    """``["a=1", 'b="x"']`` -> ``{"a": 1, "b": "x"}``: command-line ``KEY=VALUE`` items, values as JSON."""
    return {k: json.loads(v) for k, _, v in (item.partition("=") for item in items)}


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--tasks", default="push,slide,pick_and_place,reach")
    p.add_argument("--episodes", type=int, default=200)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--out", default=str(ROOT / "experiments" / "parity" / "results" / "reference.json"))
    p.add_argument("--bench-steps", type=int, default=5000, help="random-action steps per process; 0 skips")
    p.add_argument("--bench-task", default="push")
    p.add_argument("--procs", type=int, default=os.cpu_count())
    p.add_argument("--controller", action="append", default=[], metavar="ARG=VALUE",
                   help="keyword argument of the scripted controllers, e.g. --controller aim_short=0.08 (repeatable)")
    args = p.parse_args(argv)
    controller_kwargs = parse_pairs(args.controller)

    import gymnasium_robotics
    import mujoco

    out = {
        "side": "reference",
        "command": " ".join([Path(sys.executable).name, *sys.argv]),
        "date": datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%d"),
        "device": f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores (MuJoCo C)",
        "versions": {"gymnasium_robotics": gymnasium_robotics.__version__, "mujoco": mujoco.__version__},
        "load_average_at_start": os.getloadavg(),
        "episodes": args.episodes,
        "seed": args.seed,
        "controller_kwargs": controller_kwargs,
        "tasks": {},
    }
    for task in filter(None, args.tasks.split(",")):
        t0 = time.perf_counter()
        recs = run_episodes(task, args.episodes, args.seed, controller_kwargs)
        secs = time.perf_counter() - t0
        out["tasks"][task] = {"env": TASKS[task], "seconds": secs, "episodes": recs}
        sa = np.mean([r["success_any"] for r in recs])
        sf = np.mean([r["success_final"] for r in recs])
        print(f"{task:15s} success any-step {sa:.3f} final-step {sf:.3f}  ({len(recs)} episodes, {secs:.0f} s)")
    if args.bench_steps > 0:
        out["throughput"] = bench(TASKS[args.bench_task], args.bench_steps, args.procs)
        out["throughput"]["load_average_after"] = os.getloadavg()
        b = out["throughput"]
        print(f"throughput {b['env']}: {b['single_process_steps_per_s']:.0f} env-steps/s on 1 process, "
              f"{b['multi_process_steps_per_s']:.0f} on {b['procs']} ({b['speedup']:.2f}x)")
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text(json.dumps(out, indent=1))
    print("wrote", args.out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
