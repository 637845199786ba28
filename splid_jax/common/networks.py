"""The deterministic goal-conditioned policy pi_theta(s, g) and its input normaliser."""

from __future__ import annotations

import contextlib
import io
from collections.abc import Sequence

import flax.linen as nn
import jax
import jax.numpy as jnp
from flax import struct

from splid_jax.common.layers import Dense, LayerNorm

with contextlib.redirect_stdout(io.StringIO()):  # brax imports MJX, which prints a warp notice
    from brax.training.acme import running_statistics

CLIP_NORMALISED = 5.0  # normalised inputs are clipped here, as HER does, so outliers cannot dominate
# Floor of the normaliser's std (HER's eps): an input that never varied in training (Reach's locked
# fingers) would otherwise have a std near 0, and a deployment offset of 1e-3 would reach the clip.
STD_MIN = 0.01


class MLP(nn.Module):
    """MLP with orthogonal init. Defaults: leaky-ReLU and a linear output (as SPLID's reference
    code); HER's actor and critic use ReLU, and its actor a tanh output (as OpenAI Baselines and mrl)."""

    hidden: Sequence[int]
    action_size: int
    activation: str = "leaky_relu"  # a flax.linen activation: "leaky_relu" or "relu"
    tanh_output: bool = False
    layer_norm: bool = False  # LayerNorm between each hidden layer and its activation (mrl's DDPG nets)
    # The hidden layers' computation dtype ("bfloat16": mixed precision, their products on bf16 tensor cores);
    # the parameters and the output layer stay float32, so values and targets keep their resolution.
    dtype: str | None = None

    @nn.compact
    def __call__(self, x: jax.Array) -> jax.Array:
        act = getattr(nn, self.activation)
        for i, width in enumerate(self.hidden):  # flax's names, so parameters and checkpoints read as flax's layers'
            x = Dense(width, nn.initializers.orthogonal(jnp.sqrt(2.0)), self.dtype, name=f"Dense_{i}")(x)
            x = act(LayerNorm(self.dtype, name=f"LayerNorm_{i}")(x) if self.layer_norm else x)
        out_dtype = None if self.dtype is None else jnp.float32
        out = Dense(self.action_size, nn.initializers.orthogonal(0.01), out_dtype, name=f"Dense_{len(self.hidden)}")
        x = out(x)
        return jnp.tanh(x) if self.tanh_output else x


@struct.dataclass
class PolicyState:
    params: dict
    normaliser: running_statistics.RunningStatisticsState


@struct.dataclass
class Policy:
    """Pure functions around the MLP; static, so jitted code may close over it."""

    net: MLP = struct.field(pytree_node=False)
    in_size: int = struct.field(pytree_node=False)
    normalise: bool = struct.field(pytree_node=False, default=True)
    # (start, stop) of the achieved goal inside the observation: the policy is also fed goal - achieved,
    # the quantity a goal-reaching action depends on, rather than left to subtract two absolute positions,
    # in units of ``goal_unit`` (the task's success distance), so 1 is the edge of success
    achieved_slice: tuple[int, int] | None = struct.field(pytree_node=False, default=None)
    goal_unit: float = struct.field(pytree_node=False, default=1.0)

    def init(self, key: jax.Array) -> PolicyState:
        params = self.net.init(key, jnp.zeros((self.in_size,)))
        normaliser = running_statistics.init_state(jnp.zeros((self.in_size,), jnp.float32))
        return PolicyState(params=params, normaliser=normaliser)

    def features(self, obs: jax.Array, goal: jax.Array) -> jax.Array:
        """The network's input before normalisation: observation, goal and, with ``achieved_slice``,
        the goal relative to the achieved goal."""
        parts = [obs, goal]
        if self.achieved_slice is not None:
            parts.append((goal - obs[..., self.achieved_slice[0] : self.achieved_slice[1]]) / self.goal_unit)
        return jnp.concatenate(parts, axis=-1)

    def _inputs(self, pstate: PolicyState, obs: jax.Array, goal: jax.Array) -> jax.Array:
        x = self.features(obs, goal)
        if self.normalise:
            x = running_statistics.normalize(x, pstate.normaliser, max_abs_value=CLIP_NORMALISED)
        return x

    def mean(self, pstate: PolicyState, obs: jax.Array, goal: jax.Array, params=None) -> jax.Array:
        """Unclipped network output; ``params`` overrides the stored ones (for gradients)."""
        params = pstate.params if params is None else params
        return self.net.apply(params, self._inputs(pstate, obs, goal))

    def act(self, pstate: PolicyState, obs: jax.Array, goal: jax.Array) -> jax.Array:
        """The deterministic action the environment receives."""
        return jnp.clip(self.mean(pstate, obs, goal), -1.0, 1.0)

    def update_normaliser(
        self, pstate: PolicyState, obs: jax.Array, goal: jax.Array, valid: jax.Array | None = None
    ) -> PolicyState:
        """Fold a batch into the running statistics; rows where ``valid`` is False (a NaN was
        seen in that episode) carry no weight and are zeroed, since 0 * NaN would still poison them."""
        if not self.normalise:
            return pstate
        x = self.features(obs, goal).reshape(-1, self.in_size)
        w = jnp.ones(x.shape[0], jnp.float32) if valid is None else valid.reshape(-1).astype(jnp.float32)
        x = jnp.where(w[:, None] > 0, x, 0.0)
        stats = running_statistics.update(pstate.normaliser, x, weights=w, std_min_value=STD_MIN)
        return pstate.replace(normaliser=stats)


def make_policy(
    obs_size: int,
    goal_size: int,
    action_size: int,
    hidden: Sequence[int],
    normalise: bool,
    achieved_start: int | None = None,
    goal_unit: float = 1.0,
) -> Policy:
    """``achieved_start``: where the achieved goal begins in the observation (the task's
    ``achieved_goal_start``), to feed the goal relative to it; None feeds observation and goal alone."""
    achieved = None if achieved_start is None else (achieved_start, achieved_start + goal_size)
    assert achieved is None or 0 <= achieved[0] and achieved[1] <= obs_size, (achieved, obs_size)
    return Policy(
        net=MLP(hidden=tuple(hidden), action_size=action_size),
        in_size=obs_size + goal_size * (1 if achieved is None else 2),
        normalise=normalise,
        achieved_slice=achieved,
        goal_unit=float(goal_unit),
    )
