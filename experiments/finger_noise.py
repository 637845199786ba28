"""Do grasps met by chance last long enough to lift? PickAndPlace episodes whose arm follows the scripted
controller (it carries the cube toward the goal whenever the fingers hold it) while the fingers get only
exploration noise, as SPLID draws it (``draws``, ``hold_fingers``: ``--gripper-hold``), and the arm the
same noise on top. For each noise level and hold: the share of episodes in which the cube rose 5 cm above
where it rested, and the share of goals in the air reached at any step.

    python experiments/finger_noise.py --episodes 500 --sigmas 0.5 1 --holds 1 2 5 10 25 --out F.json
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import jax  # noqa: E402
import jax.numpy as jnp  # noqa: E402
import numpy as np  # noqa: E402

import envs  # noqa: E402
from envs.base import step_batch  # noqa: E402
from envs.fetch.scripted import pick_and_place  # noqa: E402
from splid_jax.learners.imitation.explore import draws, hold_fingers  # noqa: E402

LIFT = 0.05  # metres above the cube's resting height that count as lifted


def episodes(env, episodes: int):
    """A jitted ``(key, sigma, hold) -> dict`` of per-episode lift, air goal and success flags."""

    @jax.jit
    def run(key, sigma, hold):
        reset_keys, noise = draws(env, key, episodes)
        noise = hold_fingers(noise, hold)
        start = jax.vmap(env.reset)(reset_keys)

        def one(state, eps):
            arm = pick_and_place(state.obs, state.desired_goal)
            action = jnp.clip(arm.at[:, 3].set(0.0) + sigma * eps, -1.0, 1.0)  # the fingers: noise alone
            nxt = step_batch(env, state, action)
            return nxt, (nxt.achieved_goal[:, 2], nxt.success & ~nxt.invalid)

        _, (height, success) = jax.lax.scan(one, start, noise)
        rest = start.achieved_goal[:, 2]
        air = start.desired_goal[:, 2] - rest > 0.01
        return {"lifted": jnp.max(height, axis=0) - rest > LIFT, "air": air, "hit": jnp.any(success, axis=0)}

    return run


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0], allow_abbrev=False)
    p.add_argument("--episodes", type=int, default=500)
    p.add_argument("--sigmas", type=float, nargs="+", default=[0.5, 1.0])
    p.add_argument("--holds", type=int, nargs="+", default=[1, 2, 5, 10, 25])
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--out", help="write the table as JSON here")
    a = p.parse_args()
    with contextlib.redirect_stdout(io.StringIO()):  # MJX prints a warp notice on import
        env = envs.make("pick_and_place")
    run = episodes(env, a.episodes)
    t0 = time.perf_counter()
    jax.block_until_ready(run(jax.random.PRNGKey(a.seed), jnp.float32(1.0), jnp.int32(1)))
    rows = []
    print(f"compiled and ran once in {time.perf_counter() - t0:.1f} s; {a.episodes} episodes per row, device "
          f"{jax.devices()[0].platform}")  # fmt: skip
    print("sigma  hold  lifted  air goals hit  goals hit")
    for sigma in a.sigmas:
        for hold in a.holds:
            out = jax.device_get(run(jax.random.PRNGKey(a.seed), jnp.float32(sigma), jnp.int32(hold)))
            air = np.asarray(out["air"])
            row = {"sigma": sigma, "hold": hold, "lifted": float(np.mean(out["lifted"])),
                   "air_hit": float(np.mean(out["hit"][air])) if air.any() else None,
                   "hit": float(np.mean(out["hit"])), "episodes": a.episodes, "air_goals": int(air.sum())}  # fmt: skip
            rows.append(row)
            print(f"{sigma:5.2f} {hold:5d}  {row['lifted']:6.3f}  {row['air_hit']:13.3f}  {row['hit']:9.3f}")
    if a.out:
        Path(a.out).write_text(json.dumps({"device": jax.devices()[0].platform, "rows": rows}, indent=1) + "\n")


if __name__ == "__main__":
    main()
