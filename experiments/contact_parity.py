"""Whether ``envs/fused_collision.py`` gives a task's states MJX's contacts: the scripted controller's states after
each of ``--steps`` control steps, collided by MJX's driver with and without the masked contact functions.

Reports per checked step the largest differences in contact distance, position and frame (order included), the
contacts touching, and the envs whose touching contacts differ as sets (rounded to 1e-5 m): MJX's choice among
equally good manifold points is a float tie, so order may differ where the sets agree.

    python experiments/contact_parity.py --task pick_and_place --envs 16 --steps 6 16 30
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import sys
from pathlib import Path

import jax
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

with contextlib.redirect_stdout(io.StringIO()):  # MJX prints a warp notice on import
    import envs
from envs import fused_collision  # noqa: E402
from envs.fetch.scripted import CONTROLLERS  # noqa: E402


def touching(dist, pos, env: int) -> set:
    rows = np.concatenate([pos[env], dist[env][:, None]], axis=1).round(5)
    return {tuple(r) for r in rows if r[3] < 0}


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--task", default="push")
    p.add_argument("--envs", type=int, default=16)
    p.add_argument("--steps", nargs="+", type=int, default=[6, 16, 30])
    p.add_argument("--seed", type=int, default=0)
    a = p.parse_args()
    env = envs.make(a.task, solver_loops="loops")
    state = jax.jit(jax.vmap(env.reset))(jax.random.split(jax.random.PRNGKey(a.seed), a.envs))
    act, step = jax.jit(jax.vmap(CONTROLLERS[env.kind])), jax.jit(jax.vmap(env.step))
    mjxs, ours = (jax.jit(jax.vmap(lambda s, f=f: fused_collision.contacts(env, s, f))) for f in (False, True))
    for k in range(1, max(a.steps) + 1):
        state = step(state, act(state.obs, state.desired_goal))
        if k in a.steps:
            want = [np.asarray(x) for x in mjxs(state.physics)]
            got = [np.asarray(x) for x in ours(state.physics)]
            differ = sum(touching(*got[:2], e) != touching(*want[:2], e) for e in range(a.envs))
            row = {"task": a.task, "step": k, "touching": int((want[0] < 0).sum()), "envs_differing": int(differ)}
            for name, w, g in zip(("dist", "pos", "frame"), want, got, strict=True):
                row[f"max_{name}_diff"] = float(np.abs(w - g).max())
            print(json.dumps(row), flush=True)


if __name__ == "__main__":
    main()
