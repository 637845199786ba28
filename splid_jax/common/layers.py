"""Dense and LayerNorm layers as flax's (the same parameters under the same names; in float32 the same
values to rounding), whose per-feature parameters' gradients sum over the batch in two stages.

A bias or a LayerNorm scale is broadcast over the batch, so its gradient is a sum over the batch: one
column reduction per parameter per layer. XLA emits that reduction over [seeds, batch, width] with little
parallelism (a GPU block per column tile walks the whole batch), and in HER's gradient steps (5 seeds x
batch 2,000 x width 512, LayerNorm) those reductions took about 40 % of the time. Summing blocks of rows
first, then the blocks, spreads the first stage over the batch."""

from __future__ import annotations

import math
from collections.abc import Callable

import flax.linen as nn
import jax
import jax.numpy as jnp


def row_blocks(n: int) -> int:
    """The largest divisor of ``n`` at most its square root: the first stage's block count."""
    return max(d for d in range(1, math.isqrt(n) + 1) if n % d == 0)


@jax.custom_vjp
def spread(p: jax.Array, like: jax.Array) -> jax.Array:
    """``p`` ([width]) broadcast to ``like``'s shape and dtype; its gradient sums in two stages."""
    return jnp.broadcast_to(p.astype(like.dtype), like.shape)


def _spread_fwd(p, like):
    return spread(p, like), p


def _spread_bwd(p, g):
    rows = g.astype(jnp.float32).reshape(-1, g.shape[-1])
    k = row_blocks(rows.shape[0])
    # the barrier keeps XLA from merging the two sums back into one reduction
    partial = jax.lax.optimization_barrier(rows.reshape(k, -1, rows.shape[-1]).sum(axis=1))
    return partial.sum(axis=0).astype(p.dtype), None


spread.defvjp(_spread_fwd, _spread_bwd)


class Dense(nn.Module):
    """``flax.linen.Dense`` (kernel and bias)."""

    features: int
    kernel_init: Callable = nn.initializers.lecun_normal()
    dtype: str | None = None

    @nn.compact
    def __call__(self, x: jax.Array) -> jax.Array:
        kernel = self.param("kernel", self.kernel_init, (x.shape[-1], self.features))
        bias = self.param("bias", nn.initializers.zeros, (self.features,))
        x, kernel = nn.dtypes.promote_dtype(x, kernel, dtype=self.dtype)
        y = jax.lax.dot_general(x, kernel, (((x.ndim - 1,), (0,)), ((), ())))
        return y + spread(bias, y)


class LayerNorm(nn.Module):
    """``flax.linen.LayerNorm`` over the last axis (scale and bias)."""

    dtype: str | None = None

    @nn.compact
    def __call__(self, x: jax.Array) -> jax.Array:
        scale = self.param("scale", nn.initializers.ones, (x.shape[-1],))
        bias = self.param("bias", nn.initializers.zeros, (x.shape[-1],))
        y = nn.LayerNorm(use_scale=False, use_bias=False, dtype=self.dtype, name="normalised")(x)
        return y * spread(scale, y) + spread(bias, y)
