"""A trained policy's evaluation in our task with its x-y action scaled by k, the steering of its run's evaluations
kept: whether its strikes are too hard for the final step.

    PYTHONPATH=. python experiments/results/2026-11-29/slide-verdicts/scaled.py EXPORT EPISODES 1,0.75,0.5 > OUT.txt
"""

import json
import sys

import jax

from splid_jax.common.evaluation import evaluate
from splid_jax.common.subgoals import steered
from splid_jax.rollout import load_config, load_trained

run, episodes = sys.argv[1], int(sys.argv[2])
scales = [float(v) for v in sys.argv[3].split(",")]
cfg = load_config(run)
env, trainer, state, step = load_trained(cfg)
base = steered(trainer.policy, env, cfg.eval_subgoal_reach)


class Scaled:
    def __init__(self, k):
        self.k = k

    def act(self, ps, obs, goal):
        a = base.act(ps, obs, goal)
        return a.at[..., :2].multiply(self.k)


out = {"run": run.rstrip("/").split("/")[-1], "episodes": episodes}
for k in scales:
    r = jax.jit(lambda ps, key, k=k: evaluate(env, Scaled(k), ps, key, episodes))(state.policy, jax.random.PRNGKey(7))
    out[str(k)] = {m: round(float(v), 4) for m, v in r.items()}
    print(k, out[str(k)], flush=True)
print(json.dumps(out))
