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

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))
sys.path.insert(1, str(HERE / "parity"))

import jax  # noqa: E402
import numpy as np  # noqa: E402
from run_ours import rollout_fn  # noqa: E402  (the parity study's scripted episodes)

import envs  # noqa: E402
from envs.fetch.scripted import CONTROLLERS  # noqa: E402

TASKS = ("push", "slide", "pick_and_place")  # the tasks with an object to strike


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0], allow_abbrev=False)
    p.add_argument("--env", default="slide", choices=TASKS)
    p.add_argument("--episodes", type=int, default=32)
    p.add_argument("--seed", type=int, default=0)
    a = p.parse_args()
    with contextlib.redirect_stdout(io.StringIO()):  # MJX prints a warp notice on import
        env = envs.make(a.env)
    out = jax.device_get(rollout_fn(env, CONTROLLERS[a.env], a.episodes)(jax.random.PRNGKey(a.seed)))
    achieved, final = np.concatenate([out["start"][:, None], out["achieved"]], axis=1), out["success_final"]
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
