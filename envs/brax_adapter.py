"""Any ``GoalEnv`` as a ``brax.envs.base.Env``, so trainers that speak brax's interface can use the tasks.

The brax observation is ``concat(obs, desired_goal)``; ``reward`` is the task's sparse reward; ``done``
is 1 at the end of the episode (the Fetch-style tasks never terminate early, so ``info["truncation"]``
equals ``done``); ``metrics`` carries ``success`` and ``invalid`` (a NaN was seen) as floats. The
goal-conditioned ``State`` rides in ``pipeline_state``, so it can be saved and restored as it is.

Resetting. brax's ``AutoResetWrapper`` restarts every finished episode from one cached first state:
the same start and the *same goal* in every episode of a slot, which defeats goal-conditioned
training. Build the adapter with ``auto_reset=True`` instead: a finished episode restarts from
``reset`` with a fresh key carried in ``info["rng"]`` (brax's convention: the step that ends an
episode returns ``done = 1`` with the first observation of the next one). Use brax's
``VmapWrapper`` on top for batches; ``EpisodeWrapper`` also works but adds nothing here.
"""

from __future__ import annotations

import jax
import jax.numpy as jnp
from brax.envs import base as brax_base

from envs.base import GoalEnv
from envs.base import State as GoalState


class BraxGoalEnv(brax_base.Env):
    """Wrap ``env`` (a ``GoalEnv``) as a brax ``Env``; see the module docstring."""

    def __init__(self, env: GoalEnv, auto_reset: bool = False):
        self.goal_env = env
        self.auto_reset = auto_reset

    @property
    def observation_size(self) -> int:
        return self.goal_env.obs_size + self.goal_env.goal_size

    @property
    def action_size(self) -> int:
        return self.goal_env.action_size

    @property
    def backend(self) -> str:
        return "mjx" if type(self.goal_env).__module__.startswith("envs.fetch") else "jax"

    def _wrap(self, s: GoalState, info: dict) -> brax_base.State:
        done = (s.step >= self.goal_env.episode_length).astype(jnp.float32)
        info = dict(info, truncation=done)
        metrics = {"success": s.success.astype(jnp.float32), "invalid": s.invalid.astype(jnp.float32)}
        obs = jnp.concatenate([s.obs, s.desired_goal], axis=-1)
        return brax_base.State(pipeline_state=s, obs=obs, reward=s.reward, done=done, metrics=metrics, info=info)

    def reset(self, rng: jax.Array) -> brax_base.State:
        rng, key = jax.random.split(rng)
        return self._wrap(self.goal_env.reset(key), {"rng": rng})

    def step(self, state: brax_base.State, action: jax.Array) -> brax_base.State:
        s = self.goal_env.step(state.pipeline_state, action)
        out = self._wrap(s, state.info)
        if not self.auto_reset:
            return out
        rng, key = jax.random.split(state.info["rng"])
        fresh = self._wrap(self.goal_env.reset(key), state.info)
        done = out.done > 0
        pick = lambda a, b: jnp.where(jnp.reshape(done, done.shape + (1,) * (a.ndim - done.ndim)), a, b)  # noqa: E731
        return out.replace(
            pipeline_state=jax.tree_util.tree_map(pick, fresh.pipeline_state, out.pipeline_state),
            obs=pick(fresh.obs, out.obs),
            info=dict(out.info, rng=rng),
        )
