"""The contract every learner (SPLID and its ablation, GCSL, PCHID, HER, ES) meets, so that one
host loop (``splid_jax.runtime.loop``) trains, evaluates, checkpoints, resumes and sweeps any of them.

An algorithm holds only what is static (task, network, optimiser, shapes); all state flows through
arguments, so ``chunk`` can be jitted once and vmapped over the members of a sweep."""

from __future__ import annotations

from typing import Any, Protocol

import jax
import jax.numpy as jnp

from envs.base import GoalEnv
from splid_jax.common import ticks
from splid_jax.common.evaluation import evaluate
from splid_jax.common.subgoals import steered

# Keys every chunk's metrics carry (one scalar per member of a sweep), whatever the algorithm.
EVAL_KEYS = ("eval_success", "eval_success_final", "eval_return")


class Algorithm(Protocol):
    name: str
    env: GoalEnv
    cfg: Any  # the run's TrainConfig

    def init(self, key: jax.Array) -> Any:
        """The whole training state as a pytree with an ``iteration`` leaf ([] int32, completed iterations)."""

    def hyper(self, cfg: Any = None) -> Any:
        """The settings a sweep may vary per member (the registry's ``sweeps``) as a pytree of traced
        scalars (``{}`` when none), from ``cfg`` (a member's config) or the learner's own."""

    def chunk(self, state: Any, hyper: Any) -> tuple[Any, dict]:
        """Pure: ``cfg.eval_every`` iterations, then one evaluation of the deterministic policy.

        The metrics are scalars and hold ``EVAL_KEYS``, ``finite`` (bool: no NaN in parameters or
        losses) and, where the algorithm replays the simulator beyond exploration, ``select_steps``
        ([eval_every] int32, summed by the host in int64). Other keys are the algorithm's own.

        An algorithm may also split it as ``trained(state, hyper) -> (state, done)`` and ``report(state,
        hyper, done) -> metrics`` (``Chunked`` does); the host loop then compiles two programs at once."""

    def counters(self, iteration: int, select_steps: int) -> dict:
        """Exploration work after ``iteration`` iterations as exact Python ints: ``iteration``,
        ``episodes``, ``env_steps`` (exploration only, the x axis every algorithm shares) and
        ``select_steps`` (replay steps, counted apart)."""


def params_finite(params) -> jax.Array:
    """Whether every parameter is finite (no NaN, no inf)."""
    return jnp.all(jnp.stack([jnp.all(jnp.isfinite(x)) for x in jax.tree_util.tree_leaves(params)]))


class Chunked:
    """The skeleton every learner shares: ``chunk`` scans ``cfg.eval_every`` iterations, evaluates the
    deterministic policy once and checks for NaN the same way for all; ``counters`` counts exploration
    the same way for all. A learner supplies one ``iteration`` and what its chunk reports.

    Expects ``env``, ``cfg``, ``policy`` (``networks.Policy``) and a state with ``policy``, ``key``."""

    env: GoalEnv
    cfg: Any
    policy: Any

    def iteration(self, state: Any, hyper: Any) -> tuple[Any, dict]:
        """One iteration: the new state and its metrics (scalars)."""
        raise NotImplementedError

    def chunk_metrics(self, state: Any, hyper: Any, per_iteration: dict) -> dict:
        """The learner's own metrics of a chunk, from the state after it and every iteration's metrics."""
        raise NotImplementedError

    def watched(self, state: Any, per_iteration: dict) -> tuple[Any, jax.Array]:
        """The parameters that must stay finite, and a bool array that is true where the chunk's losses were."""
        raise NotImplementedError

    @property
    def episodes_per_iteration(self) -> int:
        return self.cfg.num_envs

    def chunk(self, state: Any, hyper: Any) -> tuple[Any, dict]:
        state, done = self.trained(state, hyper)
        return state, self.report(state, hyper, done)

    def trained(self, state: Any, hyper: Any) -> tuple[Any, tuple]:
        """The chunk's training, a program of its own: the host loop compiles it and ``report`` side by
        side, as XLA optimises one program on one thread. Returns the state and what ``report`` reads."""

        def one(s, _):
            s, metrics = self.iteration(s, hyper)
            ticks.tick(ticks.ITERATION, lambda: s.iteration, after=metrics)  # the iteration's last values
            return s, metrics

        state, per_iteration = jax.lax.scan(one, state, None, length=self.cfg.eval_every)
        key, k_eval = jax.random.split(state.key)
        return state.replace(key=key), (per_iteration, k_eval)

    def report(self, state: Any, hyper: Any, done: tuple) -> dict:
        """The chunk's metrics: the deterministic policy evaluated, the learner's own, NaN checks."""
        per_iteration, k_eval = done
        policy = steered(self.policy, self.env, self.cfg.eval_subgoal_reach)
        metrics = evaluate(self.env, policy, state.policy, k_eval, self.cfg.eval_episodes)
        metrics.update(self.chunk_metrics(state, hyper, per_iteration))
        params, losses_finite = self.watched(state, per_iteration)
        metrics["finite"] = params_finite(params) & jnp.all(losses_finite)
        return metrics

    def counters(self, iteration: int, select_steps: int) -> dict:
        """Work done after ``iteration`` iterations, as exact Python ints: exploration episodes and env
        steps, and the replay steps counted on the device (``select_steps``, summed by the caller)."""
        episodes = iteration * self.episodes_per_iteration
        return {
            "iteration": iteration,
            "episodes": episodes,
            "env_steps": episodes * self.env.episode_length,
            "select_steps": select_steps,
        }
