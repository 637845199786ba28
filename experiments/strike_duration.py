"""How long an object moves once struck: the scripted controller's episodes in our task, and for each the
steps between the object's first and last move of more than 1 mm. It sets how long a learning horizon must
be for a relabelled goal to be the place where the object comes to rest (Slide's ``relabel=settle``).

    python experiments/strike_duration.py --env slide --episodes 32
"""

from __future__ import annotations

import argparse
import contextlib
import io
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import jax  # noqa: E402
import numpy as np  # noqa: E402

import envs  # noqa: E402
from envs.fetch import scripted  # noqa: E402

CONTROLLERS = {"push": scripted.push, "slide": scripted.slide, "pick_and_place": scripted.pick_and_place}


def moves(env, controller, episodes: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Per episode: the achieved goal at every step [E, T + 1, G] and success at the final step [E]."""

    def one(key):
        s0 = env.reset(key)

        def body(state, _):
            nxt = env.step(state, controller(state.obs, state.desired_goal))
            return nxt, (nxt.achieved_goal, nxt.success)

        _, (achieved, success) = jax.lax.scan(body, s0, None, length=env.episode_length)
        return jax.numpy.concatenate([s0.achieved_goal[None], achieved]), success[-1]

    run = jax.jit(lambda key: jax.vmap(one)(jax.random.split(key, episodes)))
    return jax.device_get(run(jax.random.PRNGKey(seed)))


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0], allow_abbrev=False)
    p.add_argument("--env", default="slide", choices=sorted(CONTROLLERS))
    p.add_argument("--episodes", type=int, default=32)
    p.add_argument("--seed", type=int, default=0)
    a = p.parse_args()
    with contextlib.redirect_stdout(io.StringIO()):  # MJX prints a warp notice on import
        env = envs.make(a.env)
    achieved, final = moves(env, CONTROLLERS[a.env], a.episodes, a.seed)
    step = np.linalg.norm(np.diff(achieved, axis=1), axis=-1)  # [E, T]
    durations = []
    for e in range(a.episodes):
        moving = np.flatnonzero(step[e] > 1e-3)
        if len(moving):
            durations.append(moving[-1] - moving[0] + 1)
    d = np.array(durations)
    print(
        f"{a.env}: {len(d)} of {a.episodes} scripted episodes moved the object; it moved for {d.min()} to {d.max()} "
        f"steps (median {np.median(d):.0f}) of {env.episode_length}; at the goal at the final step: {final.mean():.3f}"
    )


if __name__ == "__main__":
    main()
