"""The contract every learner (SPLID and its ablation, GCSL, PCHID, HER, ES) meets, so that one
host loop (``splid_jax.runtime.loop``) trains, evaluates, checkpoints, resumes and sweeps any of them.

An algorithm holds only what is static (task, network, optimiser, shapes); all state flows through
arguments, so ``chunk`` can be jitted once and vmapped over the members of a sweep."""

from __future__ import annotations

from typing import Any, Protocol

import jax
import jax.numpy as jnp

from envs.base import GoalEnv

# Keys every chunk's metrics carry (one scalar per member of a sweep), whatever the algorithm.
EVAL_KEYS = ("eval_success", "eval_success_final", "eval_return")


class Algorithm(Protocol):
    name: str
    env: GoalEnv
    cfg: Any  # the run's TrainConfig

    def init(self, key: jax.Array) -> Any:
        """The whole training state as a pytree with an ``iteration`` leaf ([] int32, completed iterations)."""

    def hyper(self) -> Any:
        """Settings a sweep may vary per member, as a pytree of traced scalars (``{}`` when none)."""

    def chunk(self, state: Any, hyper: Any) -> tuple[Any, dict]:
        """Pure: ``cfg.eval_every`` iterations, then one evaluation of the deterministic policy.

        The metrics are scalars and hold ``EVAL_KEYS``, ``finite`` (bool: no NaN in parameters or
        losses) and, where the algorithm replays the simulator beyond exploration, ``select_steps``
        ([eval_every] int32, summed by the host in int64). Other keys are the algorithm's own."""

    def counters(self, iteration: int, select_steps: int) -> dict:
        """Exploration work after ``iteration`` iterations as exact Python ints: ``iteration``,
        ``episodes``, ``env_steps`` (exploration only, the x axis every algorithm shares) and
        ``select_steps`` (replay steps, counted apart)."""


def params_finite(params) -> jax.Array:
    return jnp.all(jnp.stack([jnp.all(jnp.isfinite(x)) for x in jax.tree_util.tree_leaves(params)]))
