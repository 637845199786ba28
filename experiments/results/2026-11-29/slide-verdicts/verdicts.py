"""Which explored pairs SELECT keeps on Slide under its first-hit verdict and under an exact-h one (the policy at g'
after exactly h steps), from one exploration of a trained SPLID policy at its run's final noise: per set of pairs,
the puck's speed where the explored path meets g' and over the h steps, the explored action's x-y size, the mean h.

    PYTHONPATH=. python experiments/results/2026-11-29/slide-verdicts/verdicts.py EXPORT ENVS SEED > OUT.json
"""

import json
import sys

import jax
import jax.numpy as jnp
import numpy as np

from splid_jax.learners.imitation.explore import draws, rollout
from splid_jax.learners.splid.relabel import hindsight, moved
from splid_jax.learners.splid.select import num_lanes, replay_queue
from splid_jax.rollout import load_config, load_trained

run, n, seed = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
cfg = load_config(run)
env, trainer, state, step = load_trained(cfg)
hyper = trainer.hyper()
it = jnp.int32(cfg.iterations)  # the trained run's last iteration: its final noise
sigma = trainer.sigma_at(it, hyper)
H = 8
reset_keys, noise = draws(env, jax.random.PRNGKey(seed), n)
traj = jax.jit(lambda ps, rk, nz: rollout(env, trainer.policy, ps, rk, nz, sigma, hyper.explore_reach))(
    state.policy, reset_keys, noise
)
T = env.episode_length
hs = hindsight(env, traj, H)
valid3 = moved(hs, jnp.int32(H))
valid = valid3.reshape(-1)
goal = hs.goal.reshape(H * T * n, -1)
starts = jax.tree_util.tree_map(lambda x: x.reshape((T * n,) + x.shape[2:]), traj.states)
flat = jnp.arange(H * T * n, dtype=jnp.int32)
start_of, h_of = flat % (T * n), flat // (T * n) + 1
lanes = num_lanes(T, n, 1.0, H)
rq = jax.jit(lambda ps, st, g, v, af: replay_queue(env, trainer.policy, ps, st, g, start_of, h_of, v, lanes, af))
first, s1 = rq(state.policy, starts, goal, valid, jnp.zeros_like(valid))
exact, s2 = rq(state.policy, starts, goal, valid, valid)
ach = np.asarray(traj.achieved)  # [T+1, N, G]
hh = np.arange(1, H + 1)[:, None, None]
tt = np.arange(T)[None, :, None]
nn = np.arange(n)[None, None, :]
later = np.minimum(tt + hh, T)
speed_at = np.linalg.norm(ach[later, nn, :2] - ach[np.maximum(later - 1, 0), nn, :2], axis=-1) / 0.04  # [H,T,N]
mean_speed = np.linalg.norm(ach[later, nn, :2] - ach[tt, nn, :2], axis=-1) / (0.04 * hh)
act = np.asarray(traj.actions)  # [T, N, A]
act_xy = np.broadcast_to(np.linalg.norm(act[None, :, :, :2], axis=-1), (H, T, n))
v = np.asarray(valid).reshape(H, T, n)
f = v & ~np.asarray(first).reshape(H, T, n)
e = v & ~np.asarray(exact).reshape(H, T, n)


def q(x, m):
    return [round(float(y), 3) for y in np.quantile(x[m], [0.25, 0.5, 0.75])] if m.any() else None


out = {
    "run": run,
    "iteration": int(it),
    "sigma": float(sigma),
    "envs": n,
    "seed": seed,
    "replay_steps": {"first_hit": int(s1), "exact_h": int(s2)},
}
for name, m in (("candidates", v), ("kept_first_hit", f), ("kept_exact_h", e)):
    out[name] = {
        "pairs": int(m.sum()),
        "puck_speed_at_goal_q": q(speed_at, m),
        "puck_mean_speed_q": q(mean_speed, m),
        "action_xy_q": q(act_xy, m),
        "h_mean": round(float(np.broadcast_to(hh, m.shape)[m].mean()), 2) if m.any() else None,
    }
print(json.dumps(out, indent=1))
