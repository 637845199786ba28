"""What a figure trains: each method's vmapped sweep (its config, its members, and its iterations
for the figure's budget of exploration episodes), and the record of it that OUT/figure.json keeps."""

from __future__ import annotations

import dataclasses
import math
import os
from collections.abc import Sequence
from typing import Any

import envs
from splid_jax.common.errors import check
from splid_jax.config import TrainConfig
from splid_jax.figures.registry import METHODS, Spec, member_name
from splid_jax.figures.settings import reads
from splid_jax.learners import registry as learners
from splid_jax.presets import TUNED

# Exploration episodes per method by default (the paper's x axes); other tasks: their default run's.
BUDGETS = {"push": 20_000, "slide": 100_000, "pick_and_place": 100_000}

# --quick: the point task, sizes that train six methods on a 2-core CPU in a few minutes.
QUICK_EPISODES = 320
QUICK_FIELDS: dict[str, Any] = dict(
    num_envs=16, eval_every=5, eval_episodes=50, bc_steps=20, batch_size=64, hidden=(32, 32), buffer_size=20_000
)
QUICK_METHOD_FIELDS: dict[str, dict[str, Any]] = {
    "her": dict(her_options="hidden=32,32,batch_size=64,update_every=0,n_batches=10,buffer_transitions=20000"),
    "her-baselines": dict(her_options="hidden=32,32,batch_size=64,n_batches=10,buffer_transitions=20000"),
    "es": dict(es_options="population=16"),
}


def default_budget(env: str) -> int:
    """The task's budget: the paper's for the Fetch tasks, the default run's (iterations x envs) otherwise."""
    if env in BUDGETS:
        return BUDGETS[env]
    return TUNED[env]["iterations"] * TUNED[env]["num_envs"]


@dataclasses.dataclass(frozen=True)
class Plan:
    """One method's vmapped sweep."""

    method: str
    base: TrainConfig
    lanes: tuple[TrainConfig, ...]
    episodes_per_iteration: int


def plan(
    spec: Spec,
    env_name: str,
    methods: Sequence[str],
    seeds: int,
    budget: int,
    sets: dict[str | None, dict[str, Any]],
    out: str,
    values: Sequence = (),
    quick: bool = False,
) -> list[Plan]:
    """Each method's sweep: its config, its members and its iterations for ``budget`` episodes.
    Builds every method's learner, so a setting none accepts fails here, before any training."""
    check(seeds >= 1, "seeds", seeds, "an integer >= 1")
    check(budget >= 1, "episodes", budget, "an integer >= 1")
    values = tuple(values) or spec.values
    made: dict[str, envs.GoalEnv] = {}
    plans = []
    for name in methods:
        algo = METHODS[name].fields["algo"]
        shared = {**(QUICK_FIELDS if quick else {}), **sets.get(None, {})}
        fields = {"env": env_name, **{k: v for k, v in shared.items() if reads(algo, k)}}
        fields.update(QUICK_METHOD_FIELDS.get(name, {}) if quick else {}, **sets.get(name, {}), **METHODS[name].fields)
        if spec.vary:
            fields[spec.vary] = max(values)  # shapes for the largest H, as a sweep's
        if "eval_every" in fields:  # else the default iterations, a multiple of the default eval_every
            fields["iterations"] = fields["eval_every"]
        probe = TrainConfig(**fields, run_dir=os.path.join(out, name))
        options = probe.env_options
        if options not in made:
            made[options] = probe.make_env()
        env = made[options]
        probe.check_env(env)
        per_iteration = learners.make_algorithm(probe, env).counters(1, 0)["episodes"]
        chunks = max(1, math.floor(budget / (per_iteration * probe.eval_every) + 0.5))  # nearest, half up
        # pchid_every left at 0 is resolved again, so PCHID's schedule follows the figure's iterations
        base = dataclasses.replace(
            probe, iterations=chunks * probe.eval_every, pchid_every=fields.get("pchid_every", 0)
        )
        grid = [(s, v) for v in (values if spec.vary else (None,)) for s in range(seeds)]
        lanes = tuple(
            dataclasses.replace(
                base,
                seed=s,
                run_dir=os.path.join(base.run_dir, member_name(s, spec.vary, v)),
                **({spec.vary: v} if spec.vary else {}),
            )
            for s, v in grid
        )
        for lane in lanes:
            lane.check_env(env)
        learners.make_algorithm(base, env)  # the run's own settings
        plans.append(Plan(name, base, lanes, per_iteration))
    return plans


def describe(plans: Sequence[Plan]) -> dict:
    """What each method runs, as OUT/figure.json keeps it: enough to resume or redraw the figure."""
    return {
        p.method: {
            "iterations": p.base.iterations,
            "episodes_per_iteration": p.episodes_per_iteration,
            "episodes": p.base.iterations * p.episodes_per_iteration,
            "config": {**p.base.to_json(), "run_dir": None},
            "members": [{**m.to_json(), "run_dir": os.path.basename(m.run_dir)} for m in p.lanes],
        }
        for p in plans
    }


def device_name() -> str:
    import jax

    device = jax.devices()[0]
    if device.platform == "cpu":
        return f"CPU ({os.cpu_count()} cores)"
    return device.device_kind
