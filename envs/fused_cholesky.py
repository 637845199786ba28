"""MJX's small dense Cholesky factor and solve, each as one Pallas kernel per env on a GPU.

Why: a Fetch substep factors the mass matrix twice (``factor_m``, and ``euler``'s implicit damping) and solves
with it twice; written out element by element (``envs/small_cholesky.py``) XLA makes each a handful of small
kernels: a Push control step at 16 envs spent 0.30 ms in ``factor_m``, 0.16 ms in ``euler`` and 0.10 ms in
``fwd_acceleration``'s solve (one H100; BENCHMARKS.md, "Time budget per stage"). Here each
factor and each solve is one kernel, its rows picked with masks as Triton needs (the masked form of
``envs/fused_solver.py``), on the matrix padded to 16 x 16 with zeros (only its first n rows and columns are
computed). The arithmetic is small_cholesky's (the upper factor MJX keeps, MuJoCo's pivot floor), summed in
another order: equal to float rounding.
"""

from __future__ import annotations

import contextlib

import jax
import jax.numpy as jnp

from envs import kernel_batch, small_cholesky
from envs.fused_solver import at_mask, col_at, pow2, row_at
from envs.small_cholesky import MIN_PIVOT


def upper_factor(a, size: int):
    """U with a = U^T U over the first ``size`` rows and columns of a padded square ``a`` (the rest zero)."""
    idx = jnp.arange(a.shape[0])
    up = jnp.zeros_like(a)
    for k in range(size):  # row k of U from the rows above it
        s = jnp.sum(jnp.where(idx[:, None] < k, up * col_at(up, k)[:, None], 0.0), axis=0)  # sum_{m<k} U[m,k] U[m,:]
        row = row_at(a, k) - s
        diag = jnp.sqrt(jnp.maximum(at_mask(row, idx == k), MIN_PIVOT))
        new = jnp.where(idx == k, diag, jnp.where(idx > k, row / diag, 0.0))
        up = jnp.where(idx[:, None] == k, new[None, :], up)
    return up


def upper_solve(up, b, size: int):
    """x with (U^T U) x = b over the first ``size`` entries (the rest zero)."""
    idx = jnp.arange(up.shape[0])
    y = jnp.zeros_like(b)
    for k in range(size):  # forward: U^T y = b
        uk = col_at(up, k)
        yk = (at_mask(b, idx == k) - jnp.sum(jnp.where(idx < k, uk * y, 0.0))) / at_mask(uk, idx == k)
        y = jnp.where(idx == k, yk, y)
    x = jnp.zeros_like(b)
    for k in reversed(range(size)):  # backward: U x = y
        uk = row_at(up, k)
        xk = (at_mask(y, idx == k) - jnp.sum(jnp.where(idx > k, uk * x, 0.0))) / at_mask(uk, idx == k)
        x = jnp.where(idx == k, xk, x)
    return x


def _call(body, out_shape, *args, interpret: bool):
    """``body`` of ``args`` as one Pallas kernel through Triton (Mosaic GPU, Pallas's default, takes no ``vmap``)."""
    from jax.experimental import pallas as pl
    from jax.experimental.pallas import triton as pl_triton

    def kernel(*refs):
        refs[-1][...] = body(*(r[...] for r in refs[:-1]))

    params = pl_triton.CompilerParams()
    return pl.pallas_call(kernel, out_shape=out_shape, interpret=interpret, compiler_params=params)(*args)


def kernel_factor(a, *, interpret: bool = False):
    """``upper_factor`` of an [n, n] matrix as one Pallas kernel (``vmap`` makes the envs its grid)."""
    n = a.shape[0]
    p = pow2(max(n, 16))
    padded = jnp.pad(a, ((0, p - n), (0, p - n)))
    out = _call(lambda x: upper_factor(x, n), jax.ShapeDtypeStruct((p, p), a.dtype), padded, interpret=interpret)
    return out[:n, :n]


def kernel_solve(up, b, *, interpret: bool = False):
    """``upper_solve`` for an [n, n] factor and an [n] right-hand side as one Pallas kernel."""
    n = up.shape[0]
    p = pow2(max(n, 16))
    padded = jnp.pad(up, ((0, p - n), (0, p - n)))
    body = lambda u, v: upper_solve(u, v, n)  # noqa: E731
    out = _call(body, jax.ShapeDtypeStruct((p,), b.dtype), padded, jnp.pad(b, (0, p - n)), interpret=interpret)
    return out[:n]


@contextlib.contextmanager
def fused_in_mjx(enabled: bool = True, max_envs: int = 0, interpret: bool = False):
    """Within the block (a trace of MJX calls), ``jax.scipy.linalg.cho_factor`` / ``cho_solve`` of a single
    small matrix run as the kernels above, at batches up to ``max_envs`` if not 0 and as small_cholesky's
    written-out arithmetic above; what they do not take (a batched call, a matrix over
    ``small_cholesky.MAX_UNROLLED``, a right-hand side of several columns) goes to small_cholesky's functions.
    ``interpret`` runs the kernels' programs with XLA, as on a CPU."""
    if not enabled:
        yield
        return
    unrolled_factor = lambda a: small_cholesky.cho_factor(a)[0]  # noqa: E731
    unrolled_solve = lambda u, b: small_cholesky.cho_solve((u, False), b)  # noqa: E731
    factor = kernel_batch.by_batch(lambda a: kernel_factor(a, interpret=interpret), unrolled_factor, max_envs)
    solve = kernel_batch.by_batch(lambda u, b: kernel_solve(u, b, interpret=interpret), unrolled_solve, max_envs)

    def cho_factor(a, lower: bool = False, overwrite_a: bool = False, check_finite: bool = True):
        if not small_cholesky.takes(a):
            return small_cholesky.cho_factor(a, lower, overwrite_a, check_finite)
        up = factor(jnp.asarray(a))
        return (up.T if lower else up), lower

    def cho_solve(c_and_lower, b, overwrite_b: bool = False, check_finite: bool = True):
        c, lower = c_and_lower
        b = jnp.asarray(b)
        if not small_cholesky.takes(c) or b.ndim != 1 or b.shape[0] != c.shape[0]:
            return small_cholesky.cho_solve(c_and_lower, b, overwrite_b, check_finite)
        return solve(c.T if lower else c, b)

    with small_cholesky.linalg_swapped(cho_factor, cho_solve):
        yield
