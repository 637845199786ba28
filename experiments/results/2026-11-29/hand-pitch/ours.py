"""A Slide run's policy in our task with task options added (e.g. ``hand_pitch=1``), from the project's evaluation draw
(``rollout.rollout`` from ``PRNGKey(0)``), as ``evaluate --reference`` plays our side:

    PYTHONPATH=. python experiments/results/2026-11-29/hand-pitch/ours.py RUN OPTIONS EPISODES >> ours.jsonl
"""

import json
import sys

import jax
import numpy as np

from splid_jax.reference.policy import load_run
from splid_jax.rollout import rollout

run, options, episodes = sys.argv[1], sys.argv[2], int(sys.argv[3])
cfg, env, policy, pstate, step = load_run(run, env_options=options)
states = jax.jit(lambda k: rollout(env, policy, pstate, k, episodes))(jax.random.PRNGKey(0))
success = np.asarray(states.success[1:])
print(json.dumps(dict(run=run.rstrip("/").split("/")[-1], step=int(step), options=options, episodes=episodes,
                      any=float(success.any(0).mean()), final=float(success[-1].mean()))))  # fmt: skip
