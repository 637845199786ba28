"""How the object moves under exploration's noise alone, in our task and in Gymnasium-Robotics' `Fetch*-v4`:
the action is N(0, sigma^2) clipped to [-1, 1] every step (SPLID's exploration around a policy that outputs
zero), so the object moves only where the noise happens to strike it.

    python experiments/random_lift.py --env pick_and_place --episodes 200 --out F.json

Per simulator: the share of steps with the object lifted more than 1 and 5 cm above where it rests, the share of
episodes in which it ever is, the highest lift, the object's speed on its fastest step, and the share of
episodes where it ends off the table (5 cm below its resting height). Both simulators get their own resets
(the same distribution, not the same states)."""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import time

import numpy as np

TASKS = ("push", "slide", "pick_and_place")


def summarise(z: np.ndarray, pos: np.ndarray, dt: float) -> dict:
    """``z``: [E, T + 1] object height above its resting height; ``pos``: [E, T + 1, 3] object positions."""
    speed = np.linalg.norm(np.diff(pos, axis=1), axis=-1) / dt
    lift = z[:, 1:]
    return {
        "episodes": int(z.shape[0]),
        "steps_lifted_1cm": float(np.mean(lift > 0.01)),
        "steps_lifted_5cm": float(np.mean(lift > 0.05)),
        "episodes_lifted_1cm": float(np.mean(np.any(lift > 0.01, axis=1))),
        "episodes_lifted_5cm": float(np.mean(np.any(lift > 0.05, axis=1))),
        "lift_max_median": float(np.median(np.max(lift, axis=1))),
        "lift_max_p99": float(np.percentile(np.max(lift, axis=1), 99)),
        "speed_max_median": float(np.median(np.max(speed, axis=1))),
        "speed_max_p99": float(np.percentile(np.max(speed, axis=1), 99)),
        "episodes_off_table": float(np.mean(z[:, -1] < -0.05)),
        "episodes_moved_2cm": float(np.mean(np.linalg.norm(pos[:, -1] - pos[:, 0], axis=-1) > 0.02)),
    }


def ours(env_name: str, episodes: int, sigma: float, seed: int, options: dict) -> dict:
    import jax
    import jax.numpy as jnp

    import envs
    from envs.base import step_batch

    with contextlib.redirect_stdout(io.StringIO()):  # MJX prints a warp notice on import
        env = envs.make(env_name, **options).evaluation_task()
    rest = env.layout.object_rest_z
    k_reset, k_noise = jax.random.split(jax.random.PRNGKey(seed))
    start = jax.vmap(env.reset)(jax.random.split(k_reset, episodes))
    noise = sigma * jax.random.normal(k_noise, (env.episode_length, episodes, env.action_size))

    def one(state, eps):
        nxt = step_batch(env, state, jnp.clip(eps, -1.0, 1.0))
        return nxt, nxt.achieved_goal

    t0 = time.perf_counter()
    _, achieved = jax.jit(lambda s, n: jax.lax.scan(one, s, n))(start, noise)
    pos = np.concatenate([np.asarray(start.achieved_goal)[:, None], np.swapaxes(np.asarray(achieved), 0, 1)], axis=1)
    out = summarise(pos[..., 2] - rest, pos, env.dt)
    out["wall_s"] = time.perf_counter() - t0
    return out


def reference(env_name: str, episodes: int, sigma: float, seed: int) -> dict:
    from splid_jax.reference.extra import make_reference

    env = make_reference(env_name)
    rng = np.random.default_rng(seed)
    heights, positions = [], []
    for ep in range(episodes):
        obs, _ = env.reset(seed=seed + ep)
        rest = obs["achieved_goal"][2]
        pos = [obs["achieved_goal"].copy()]
        for _ in range(env.spec.max_episode_steps):
            obs, *_ = env.step(np.clip(sigma * rng.standard_normal(4), -1.0, 1.0))
            pos.append(obs["achieved_goal"].copy())
        pos = np.asarray(pos)
        positions.append(pos)
        heights.append(pos[:, 2] - rest)
    dt = env.unwrapped.dt
    env.close()
    return summarise(np.asarray(heights), np.asarray(positions), dt)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0], allow_abbrev=False)
    p.add_argument("--env", default="pick_and_place", choices=TASKS)
    p.add_argument("--episodes", type=int, default=200)
    p.add_argument("--sigma", type=float, default=1.0)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--env-options", default="", help="our task's fields, KEY=VALUE[,KEY=VALUE]")
    p.add_argument("--no-reference", action="store_true")
    p.add_argument("--out", default="")
    a = p.parse_args()
    from splid_jax.common.values import parse_overrides

    options = parse_overrides(a.env_options, "env-options") if a.env_options else {}
    record = {"env": a.env, "sigma": a.sigma, "seed": a.seed, "env_options": options, "date": time.strftime("%Y-%m-%d")}
    record["ours"] = ours(a.env, a.episodes, a.sigma, a.seed, options)
    print("ours", json.dumps(record["ours"]), flush=True)
    if not a.no_reference:
        record["reference"] = reference(a.env, a.episodes, a.sigma, a.seed)
        print("reference", json.dumps(record["reference"]), flush=True)
    if a.out:
        with open(a.out, "w") as fh:
            json.dump(record, fh, indent=1)


if __name__ == "__main__":
    main()
