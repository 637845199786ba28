"""A GPU kernel that runs one env per program at small batches, and XLA's batched code at large ones.

Why: one env per program (the Pallas kernels in ``envs/fused_*.py``) wins where a step's envs are few, the
GPU's time going to launches rather than arithmetic, and loses at thousands of envs, where XLA's batched
operations fill the GPU better (experiments/NOTES.md, "Physics kernels, HER's updates and the host loop"). A step
runs at both sizes in one program (exploration at 125 envs, SELECT's replays at thousands), and the function being
batched does not see its batch; ``vmap`` does, so the choice is made in a custom batching rule.
"""

from __future__ import annotations

from collections.abc import Callable

import jax


def by_batch(kernel: Callable, batched: Callable, max_envs: int) -> Callable:
    """``kernel(*args)`` unbatched and under a ``vmap`` of at most ``max_envs``; ``batched`` (the same function
    written for XLA) under a larger one. Only the innermost ``vmap`` counts: an enclosing one (a sweep's
    members) batches whichever was chosen. ``max_envs`` 0 keeps the kernel at every size."""
    if not max_envs:
        return kernel

    @jax.custom_batching.custom_vmap
    def one(*args):
        return kernel(*args)

    @one.def_vmap
    def rule(axis_size, in_batched, *args):
        chosen = kernel if axis_size <= max_envs else batched
        axes = tuple(jax.tree.map(lambda b: 0 if b else None, flags) for flags in in_batched)
        out = jax.vmap(chosen, in_axes=axes)(*args)
        return out, jax.tree.map(lambda _: True, out)

    return one
