"""A LayerNorm whose backward pass is written out (custom_vjp), to test against autodiff's."""

import flax.linen as nn
import jax
import jax.numpy as jnp

from splid_jax.common.layers import row_blocks

EPS = 1e-6


def _sum_rows(v):
    rows = v.reshape(-1, v.shape[-1])
    k = row_blocks(rows.shape[0])
    return jax.lax.optimization_barrier(rows.reshape(k, -1, rows.shape[-1]).sum(axis=1)).sum(axis=0)


@jax.custom_vjp
def layer_norm(x, scale, bias):
    return _fwd(x, scale, bias)[0]


def _fwd(x, scale, bias):
    xf = x.astype(jnp.float32)
    mu = jnp.mean(xf, axis=-1, keepdims=True)
    var = jnp.mean(jnp.square(xf - mu), axis=-1, keepdims=True)
    rstd = jax.lax.rsqrt(var + EPS)
    xhat = (xf - mu) * rstd
    y = (xhat * scale + bias).astype(x.dtype)
    return y, (x, mu, rstd, scale)


def _bwd(res, dy):
    x, mu, rstd, scale = res
    xhat = (x.astype(jnp.float32) - mu) * rstd
    dyf = dy.astype(jnp.float32)
    g = dyf * scale
    dx = rstd * (g - jnp.mean(g, axis=-1, keepdims=True) - xhat * jnp.mean(g * xhat, axis=-1, keepdims=True))
    return dx.astype(x.dtype), _sum_rows(dyf * xhat), _sum_rows(dyf)


layer_norm.defvjp(_fwd, _bwd)


class FastLayerNorm(nn.Module):
    dtype: str | None = None

    @nn.compact
    def __call__(self, x):
        scale = self.param("scale", nn.initializers.ones, (x.shape[-1],))
        bias = self.param("bias", nn.initializers.zeros, (x.shape[-1],))
        return layer_norm(x if self.dtype is None else x.astype(self.dtype), scale, bias)
