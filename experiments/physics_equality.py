"""Whether the physics kernels step the Fetch tasks as stock MJX does: each task stepped with ``physics=kernels``
and ``physics=mjx`` side by side in one program, from the same starts, for ``--steps`` control steps at each of
``--batches``.

The actions are the scripted controller's (``envs/fetch/scripted.py``) on each backend's own observation, plus the
same Gaussian noise for both, so the states a policy reaches (contacts, grasps, strikes) are covered. Episodes run
back to back (a fresh start every episode length, the same for both backends). Reported per task and batch: the
largest absolute difference of qpos and of qvel over every step and env, the same for the median env and the 99th
percentile env (contacts amplify float rounding: a few envs part after a contact whichever implementation is
compared, the median env shows whether the arithmetic is the same), each backend's success rate, and the share of
episodes whose success (at any step) agrees. Writes JSON to ``--out`` and a markdown table beside it (``.md``).

    python experiments/physics_equality.py --out experiments/results/physics_equality.json          # on a GPU
    python experiments/physics_equality.py --out /tmp/eq.json --tasks push --batches 2 --steps 4    # CPU smoke test
"""

from __future__ import annotations

import argparse
import importlib.metadata
import json
import math
import sys
import time
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import envs  # noqa: E402
from envs import physics  # noqa: E402
from envs.base import step_batch  # noqa: E402
from envs.fetch.scripted import CONTROLLERS  # noqa: E402
from splid_jax.common.values import parse_overrides  # noqa: E402

TASKS = ("push", "slide", "pick_and_place")


def compare(task: str, batch: int, steps: int, noise: float, seed: int, options: dict) -> dict:
    """One task at one batch: the two backends stepped side by side; differences and successes as JSON."""
    kernels, stock = (envs.make(task, physics=p, **options) for p in ("kernels", "mjx"))
    length = min(steps, kernels.episode_length)
    episodes = math.ceil(steps / length)
    act = jax.vmap(CONTROLLERS[task])

    def episode(carry, key):
        k_reset, k_noise = jax.random.split(key)
        start = jax.vmap(kernels.reset)(jax.random.split(k_reset, batch))  # reset is the same on both backends

        def step(c, k):
            (sk, sm), (dq, dv) = c
            n = noise * jax.random.normal(k, (batch, kernels.action_size))
            sk = step_batch(kernels, sk, act(sk.obs, sk.desired_goal) + n)
            sm = step_batch(stock, sm, act(sm.obs, sm.desired_goal) + n)
            dq = jnp.maximum(dq, jnp.max(jnp.abs(sk.physics.qpos - sm.physics.qpos), axis=-1))
            dv = jnp.maximum(dv, jnp.max(jnp.abs(sk.physics.qvel - sm.physics.qvel), axis=-1))
            return ((sk, sm), (dq, dv)), (sk.success, sm.success)

        (_, diffs), (ok_k, ok_m) = jax.lax.scan(step, ((start, start), carry), jax.random.split(k_noise, length))
        return diffs, (jnp.any(ok_k, axis=0), jnp.any(ok_m, axis=0))

    def run(key):
        zeros = (jnp.zeros(batch), jnp.zeros(batch))
        return jax.lax.scan(episode, zeros, jax.random.split(key, episodes))

    t0 = time.perf_counter()
    (dq, dv), (ok_k, ok_m) = jax.block_until_ready(jax.jit(run)(jax.random.PRNGKey(seed)))
    dq, dv, ok_k, ok_m = (np.asarray(x) for x in (dq, dv, ok_k, ok_m))

    def spread(d):
        return {"max": float(d.max()), "p99_env": float(np.quantile(d, 0.99)), "median_env": float(np.median(d))}

    return {
        "task": task,
        "batch": batch,
        "steps": episodes * length,
        "episodes": int(ok_k.size),
        "qpos_abs_diff": spread(dq),
        "qvel_abs_diff": spread(dv),
        "success_kernels": float(ok_k.mean()),
        "success_mjx": float(ok_m.mean()),
        "success_agreement": float((ok_k == ok_m).mean()),
        "wall_s": round(time.perf_counter() - t0, 1),
        "physics_in_use": [kernels.physics_in_use(), stock.physics_in_use()],
    }


def markdown(record: dict) -> str:
    versions = f"mujoco {record['mujoco']}, mujoco-mjx {record['mujoco_mjx']}, jax {record['jax']}"
    options = record["options"] or "the defaults"
    head = f"Physics kernels against stock MJX on {record['device']} ({versions}); options: {options}\n\n"
    rows = [
        "| task | batch | steps | max qpos diff | median env | max qvel diff | median env | success kernels | "
        "success mjx | agreement |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for r in record["results"]:
        q, v = r["qpos_abs_diff"], r["qvel_abs_diff"]
        rows.append(f"| {r['task']} | {r['batch']} | {r['steps']} | {q['max']:.2e} | {q['median_env']:.2e} | "
                    f"{v['max']:.2e} | {v['median_env']:.2e} | {r['success_kernels']:.3f} | {r['success_mjx']:.3f} | "
                    f"{r['success_agreement']:.3f} |")  # fmt: skip
    return head + "\n".join(rows) + "\n"


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--out", type=Path, required=True, help="the JSON summary; the markdown table goes beside it (.md)")
    p.add_argument("--tasks", nargs="+", default=list(TASKS), choices=sorted(CONTROLLERS))
    p.add_argument("--batches", nargs="+", type=int, default=[16, 125, 1024, 4096])
    p.add_argument("--steps", type=int, default=1000, help="control steps per batch, in whole episodes")
    p.add_argument("--noise", type=float, default=0.2, help="Gaussian action noise added to the controller's")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--options", default="", help="task options both backends take, KEY=VALUE[,KEY=VALUE...]")
    a = p.parse_args()
    if physics.in_use("kernels") != "kernels":
        print(f"the kernels do not run on this MuJoCo ({physics.installed()}): nothing to compare", file=sys.stderr)
        return 2
    options = parse_overrides(a.options)
    record = {
        "device": str(jax.devices()[0].device_kind),
        "backend": jax.default_backend(),
        "mujoco": physics.installed()[0],
        "mujoco_mjx": physics.installed()[1],
        "jax": importlib.metadata.version("jax"),
        "options": a.options,
        "noise": a.noise,
        "seed": a.seed,
        "results": [],
    }
    for task in a.tasks:
        for batch in a.batches:
            r = compare(task, batch, a.steps, a.noise, a.seed, options)
            print(json.dumps(r), flush=True)
            record["results"].append(r)
    a.out.parent.mkdir(parents=True, exist_ok=True)
    a.out.write_text(json.dumps(record, indent=2) + "\n")
    a.out.with_suffix(".md").write_text(markdown(record))
    print(markdown(record))
    return 0


if __name__ == "__main__":
    sys.exit(main())
