"""Every task's and learner's defaults, in one place: the ``tuned`` preset (the default) and the
``paper`` preset (``--preset paper``) beside it. A setting given on the command line replaces the
preset's; a run's config.json records the resolved values, so a preset changed later leaves a
recorded run as it ran.

``tuned`` adds to Algorithm 2 what learned best where it was compared, each chosen on tuning seeds and
reported on fresh ones; the "why" is an experiments/NOTES.md section ("Task defaults" lists them):

| addition (settings) | tasks | why (NOTES.md section) |
|---|---|---|
| held goals (relabel hold), cloned with the zero action | Push stop; Slide, P&P hold | "Final-step success on Push" |
| H falling 12 -> 8 with the noise (horizon, horizon_end) | Push | "Push: the default's arms" |
| noise annealed to sigma_end x sigma (sigma_end, sigma_anneal) | Push, Slide, P&P | "Push: the default's arms" |
| a Polyak-averaged acting policy (policy_ema) | Push, Slide, P&P | "Push: the default's arms" |
| a cloning window widening to the buffer (buffer_window, _grow) | Push | "Push: the default's arms" |
| steered at subgoals (*_subgoal_reach) | Push, Slide, P&P | "PickAndPlace: subgoals at evaluation" |
| relative goal, raw inputs, Adam 5e-4 (relative_goal, ...) | Fetch tasks | "Push: the default's arms" |
| half the envs per iteration, twice the iterations (num_envs 256) | P&P | "Envs per iteration against iterations" |

Held goals keep a reached goal (Algorithm 2 never stores one, so the policy pushes through it); a falling
H learns early and judges the final approach; less noise late and an averaged acting policy make the
policy precise; the widening window clones the newest pairs first and keeps the learning phase's later;
subgoals keep far goals within those a policy is taught; PickAndPlace's smaller iterations clone and select
with a newer policy twice as often for the same episodes.

``paper`` is Algorithm 2 as the paper states it; where the paper is silent, the authors' released code
(decisionforce/ESPD); every value's source is in ``PAPER_SOURCES``. HER's ``tuned`` is spitis/mrl's
DDPG+HER (HerConfig's defaults), its ``paper`` OpenAI Baselines' protocol (8 workers); GCSL's and PCHID's
share SPLID's cloning settings, ES keeps Salimans et al.'s; SPLID without SELECT is ``--preset paper
--no-select``."""

from __future__ import annotations

from typing import Any

from splid_jax.common.values import options_text
from splid_jax.learners.her.config import BASELINES, BASELINES_WORKERS, HerConfig

PRESETS = {
    "tuned": "what learned best where it was compared; splid_jax/presets.py says what and why",
    "paper": "Algorithm 2 at the paper's settings, the authors' code where the paper is silent; HER: OpenAI Baselines",
}

_POINT = dict(
    relabel="paper", horizon=8, horizon_end=0, iterations=100, select_lanes=1.0, num_envs=32, buffer_size=200_000,
    buffer_window=0, buffer_window_grow=0, batch_size=256, bc_steps=100, bc_reuse=0.0, learning_rate=1e-3,
    held_share=0.0, optimiser="adam", policy_ema=0.0, hidden=(64, 64, 64), normalise=True, relative_goal=False,
    sigma_end=1.0, sigma_anneal=1, eval_every=5, eval_episodes=200, eval_subgoal_reach=0.0, explore_subgoal_reach=0.0,
)  # fmt: skip
_FETCH = {**_POINT, "iterations": 200, "num_envs": 256, "buffer_size": 1_000_000, "batch_size": 1024}
_FETCH.update(bc_steps=200, hidden=(256, 256, 256), eval_episodes=500)
# PickAndPlace's and Slide's: held goals, exploring and evaluated steered at subgoals
_HELD_STEERED: dict[str, Any] = {
    **_FETCH, "num_envs": 512, "relabel": "hold", "normalise": False, "relative_goal": True, "sigma_end": 0.5,
    "sigma_anneal": 50, "policy_ema": 0.98, "learning_rate": 5e-4, "eval_subgoal_reach": 0.1,
    "explore_subgoal_reach": 0.1,
}  # fmt: skip

# The tuned preset: every task's run settings and the cloning learners' (SPLID's) settings. Push's window: the
# newest 50k pairs alone learn fast and fall late as the buffer turns over, all 200k hold the peak but start slower;
# widening from one to the other over 200 iterations keeps both. Its subgoals' 0.1 m lies near the buffer's median
# goal distance from the cube. Slide stops where its final step peaks (100k pairs reach the same peak later);
# PickAndPlace's 50k pairs turned over in a few iterations as SELECT's intake shrank, and its final step fell.
TUNED: dict[str, dict[str, Any]] = {
    "point": _POINT,
    "reach": {**_FETCH, "iterations": 20, "num_envs": 64, "relative_goal": True},
    "push": {
        **_FETCH, "iterations": 80, "num_envs": 125, "relabel": "stop", "horizon": 12, "horizon_end": 8,
        "normalise": False, "relative_goal": True, "sigma_end": 0.2, "sigma_anneal": 80, "buffer_size": 200_000,
        "buffer_window": 50_000, "buffer_window_grow": 200, "policy_ema": 0.98, "learning_rate": 5e-4,
        "eval_subgoal_reach": 0.1, "explore_subgoal_reach": 0.1,
    },
    "slide": {**_HELD_STEERED, "iterations": 70, "buffer_size": 50_000},
    "pick_and_place": {
        **_HELD_STEERED, "env_options": "grasped_starts=0.5", "num_envs": 256, "iterations": 80, "sigma_anneal": 100,
        "buffer_size": 100_000,
    },
    "reacher": {**_POINT, "iterations": 40},
    "sawyer_door": {**_POINT, "iterations": 40},
}  # fmt: skip

# The imitation baselines explore towards the goal, as their papers do, and clone Push's newest 50,000 pairs,
# the buffer they were measured with
_BASELINES = {task: {"explore_subgoal_reach": 0.0} for task in ("push", "slide", "pick_and_place")}
_BASELINES["push"].update(buffer_size=50_000, buffer_window=0, buffer_window_grow=0)
# HER on the Fetch tasks runs as mrl's benchmarks: 8 envs, one episode each per iteration, evaluated every 200
# episodes, to mrl's budgets (Push and PickAndPlace 1M transitions, Slide 2.5M) on the standard tasks (no grasped
# starts)
_HER_FETCH = dict(num_envs=8, eval_every=25)
_HER_TASKS = {
    "reach": {**_HER_FETCH, "iterations": 250},
    "push": {**_HER_FETCH, "iterations": 2500},
    "slide": {**_HER_FETCH, "iterations": 6250},
    "pick_and_place": {**_HER_FETCH, "iterations": 2500, "env_options": "grasped_starts=0"},
}
# the tuned preset: each learner's own settings per task, replacing the task's above
TUNED_LEARNERS: dict[str, dict[str, dict[str, Any]]] = {
    "gcsl": _BASELINES,
    "pchid": {**_BASELINES, "push": {**_BASELINES["push"], "horizon": 8}},  # SPLID's falling H is not PCHID's
    "her": _HER_TASKS,
}

# (value, source) of every setting the paper preset gives SPLID; "ESPD" is the authors' released code
# (decisionforce/ESPD: args.py, model.py, espd.py)
PAPER_SOURCES: dict[str, tuple[Any, str]] = {
    "relabel": ("paper", "paper, Algorithm 2 lines 12-19: every g' = m(s_{t+h}) the object moved to"),
    "select": (True, "paper, Algorithm 2 line 15 (--no-select: the paper's ablation)"),
    "horizon": (8, "paper, section 4.1: H = 8 in all three environments"),
    "horizon_end": (0, "paper: H throughout"),
    "sigma": (1.0, "paper, section 4.1: sigma = 1 (ESPD's --factor is 1.5)"),
    "sigma_end": (1.0, "paper: sigma throughout"),
    "sigma_anneal": (1, "paper: sigma throughout"),
    "policy_ema": (0.0, "paper: theta acts"),
    "explore_subgoal_reach": (0.0, "paper: the behaviour policy pursues g"),
    "eval_subgoal_reach": (0.0, "paper: the policy pursues g"),
    "buffer_size": (100_000, "ESPD: replay_buffer_size_IER"),
    "buffer_window": (0, "paper: the minibatch is sampled from the buffer B"),
    "buffer_window_grow": (0, "paper: the whole buffer"),
    "hidden": ((64, 64, 64), "ESPD: model.py's 64 x 3 actor (leaky ReLU there, ReLU here)"),
    "normalise": (False, "ESPD: raw observation and goal"),
    "relative_goal": (False, "ESPD: observation and desired goal"),
    "optimiser": ("rmsprop", "ESPD: RMSprop"),
    "learning_rate": (3e-4, "ESPD: --lr-hid"),
    "batch_size": (25, "ESPD: --minibatch-size"),
    "bc_reuse": (30.0, "ESPD: --num-epoch 30 x new pairs / minibatch steps per iteration"),
    "bc_steps": (5_000, "a cap ESPD does not have: reached above 4,166 new pairs in an iteration"),
    "num_envs": (50, "ESPD: --batch-size 2,500 steps per iteration, 50 episodes of 50 steps"),
    "env_options": ("", "paper: the tasks' own starts (tuned PickAndPlace's grasped starts are HER's protocol)"),
}
PAPER_SPLID = {name: value for name, (value, _) in PAPER_SOURCES.items()}
# HER's paper preset is OpenAI Baselines' DDPG+HER (HerConfig's BASELINES), whose curves ran 8 MPI workers of 2
# episodes each per cycle (num_envs 16) and evaluated every epoch of 50 cycles, on the tasks' own starts
_HER_PAPER = {"her_options": options_text(HerConfig(), **BASELINES), "env_options": ""}
_HER_PAPER.update(num_envs=2 * BASELINES_WORKERS, eval_every=50)
PAPER_LEARNERS: dict[str, dict[str, Any]] = {
    "splid": PAPER_SPLID,
    "gcsl": {**PAPER_SPLID, "gcsl_relabel": "final"},  # paper, section 4: GCSL relabels to the last step
    "pchid": {**PAPER_SPLID, "pchid_every": 0},  # ESPD's --Horizon-max 8 for PCHID; H grows 1..8 over half the run
    "her": _HER_PAPER,
    "es": {},  # ES's own defaults are Salimans et al.'s
}
# the paper preset's budgets: HER's as Baselines' Figure 3 runs (Push 20,000 episodes, Slide and PickAndPlace
# 51,200); the cloning learners' the tuned preset's episodes at 50 per iteration, in whole chunks
_CLONING_ITERATIONS = {"point": 65, "reach": 25, "push": 200, "slide": 715, "pick_and_place": 410}
PAPER_ITERATIONS = {
    "her": {"reach": 250, "push": 1250, "slide": 3200, "pick_and_place": 3200},
    **dict.fromkeys(("splid", "gcsl", "pchid"), _CLONING_ITERATIONS),
}


def defaults(env: str, algo: str, preset: str) -> dict[str, Any]:
    """The settings ``preset`` gives learner ``algo`` on task ``env``; the caller's values replace them."""
    tuned = {**TUNED[env], **TUNED_LEARNERS.get(algo, {}).get(env, {})}
    if preset == "tuned":
        return tuned
    budget = PAPER_ITERATIONS.get(algo, {})
    return {**tuned, **PAPER_LEARNERS[algo], **({"iterations": budget[env]} if env in budget else {})}
