"""Cholesky factor-and-solve of the small dense matrices in an MJX step, written out element by element.

Why: an MJX step of a Fetch-style task factors and solves a dense nv x nv system seven times per
substep (the mass matrix, the implicit-damping Euler update, and the Newton solver's Hessian at its
start and at each iteration), each through ``jax.scipy.linalg.cho_factor`` / ``cho_solve``. Under
``vmap`` on a GPU those become batched cuSOLVER / cuBLAS calls that are slow for such tiny matrices,
several times slower than the same arithmetic unrolled here, which XLA fuses into element-wise kernels,
and Push's step with them (``experiments/NOTES.md``, "Unrolled small Cholesky solves").
It is the same algorithm (the Cholesky-Banachiewicz order), so results agree with the library's to
float rounding.

``UNROLLED`` is what ``envs/mjx_patch.py`` puts in place of ``jax.scipy.linalg``'s two functions for a
task's step. Matrices larger than ``MAX_UNROLLED`` (the op count grows as n^3) and batched inputs go to the
library functions.
"""

from __future__ import annotations

import jax
import jax.numpy as jnp
import jax.scipy.linalg as jsl

MAX_UNROLLED = 16
MIN_PIVOT = 1e-15  # mjMINVAL: MuJoCo's floor for a Cholesky pivot

_LIBRARY = (jsl.cho_factor, jsl.cho_solve)


def lower_factor(a: jax.Array) -> jax.Array:
    """L with a = L L^T for a symmetric positive definite [n, n] matrix."""
    n = a.shape[-1]
    cols: list[list[jax.Array | None]] = [[None] * n for _ in range(n)]  # cols[i][j] = L[i, j], j <= i
    for j in range(n):
        pivot = a[j, j]
        for k in range(j):
            pivot = pivot - cols[j][k] * cols[j][k]
        diag = jnp.sqrt(jnp.maximum(pivot, MIN_PIVOT))
        cols[j][j] = diag
        for i in range(j + 1, n):
            s = a[i, j]
            for k in range(j):
                s = s - cols[i][k] * cols[j][k]
            cols[i][j] = s / diag
    zero = jnp.zeros((), a.dtype)
    return jnp.stack([jnp.stack([cols[i][j] if j <= i else zero for j in range(n)]) for i in range(n)])


def lower_solve(low: jax.Array, b: jax.Array) -> jax.Array:
    """x with (L L^T) x = b, by forward then backward substitution; b is [n] or [n, k]."""
    n = low.shape[-1]
    y: list[jax.Array] = []
    for i in range(n):
        s = b[i]
        for k in range(i):
            s = s - low[i, k] * y[k]
        y.append(s / low[i, i])
    x: list[jax.Array | None] = [None] * n
    for i in reversed(range(n)):
        s = y[i]
        for k in range(i + 1, n):
            s = s - low[k, i] * x[k]
        x[i] = s / low[i, i]
    return jnp.stack(x)


def _unrolled(a) -> bool:
    return jnp.ndim(a) == 2 and a.shape[0] == a.shape[1] and a.shape[0] <= MAX_UNROLLED


def cho_factor(a, lower: bool = False, overwrite_a: bool = False, check_finite: bool = True):
    """``jax.scipy.linalg.cho_factor``: (the upper factor, or the lower one if ``lower``, ``lower``)."""
    if not _unrolled(a):
        return _LIBRARY[0](a, lower=lower, overwrite_a=overwrite_a, check_finite=check_finite)
    # The barrier makes XLA compute the matrix once, before the factorisation's fused kernel, instead of
    # fusing its producer in, which made the substep and its Newton solve faster. The same barrier on the outputs
    # made the step several times slower.
    low = lower_factor(jax.lax.optimization_barrier(jnp.asarray(a)))
    return (low if lower else low.T), lower


def cho_solve(c_and_lower, b, overwrite_b: bool = False, check_finite: bool = True):
    """``jax.scipy.linalg.cho_solve`` for a factor from either ``cho_factor``."""
    c, lower = c_and_lower
    b = jnp.asarray(b)
    if not _unrolled(c) or b.ndim not in (1, 2) or b.shape[0] != c.shape[0]:
        return _LIBRARY[1](c_and_lower, b, overwrite_b=overwrite_b, check_finite=check_finite)
    return lower_solve(c if lower else c.T, b)


UNROLLED = (cho_factor, cho_solve)
