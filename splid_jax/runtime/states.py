"""How a run's state is made and placed: built from its keys (one member at a time where XLA:CPU needs it),
strongly typed and put on the devices the run's placement names, so a fresh state and a restored one reach
the compiled chunk alike."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import jax
import jax.numpy as jnp


def initial_state(init: Callable[[jax.Array], Any], keys: jax.Array, stacked: bool, one_by_one: bool) -> Any:
    """``init`` of each key, stacked along a leading axis for a sweep. ``one_by_one`` builds each member
    alone and stacks them, for XLA:CPU: jaxlib 0.10.2 never finishes the vmapped init of five Push members
    (each member alone, or four together, takes a second). A member's state depends on its key alone, so
    both ways give the same arrays."""
    if not stacked:
        return jax.jit(init)(keys)
    if not one_by_one:
        return jax.jit(jax.vmap(init))(keys)
    one = jax.jit(init)
    return jax.tree.map(lambda *x: jnp.stack(x), *[one(k) for k in keys])


def canonical(tree, sharding):
    """Strongly typed arrays placed as ``sharding`` says, whether they come from init or a checkpoint,
    so the compiled chunk takes a resumed state as it takes a fresh one."""
    # made on one device, then placed: XLA:CPU can hang in a later program that reads an array a
    # multi-device jit wrote through out_shardings
    return jax.device_put(jax.jit(_strong)(tree), sharding)


def _strong(tree):
    return jax.tree.map(lambda x: jnp.asarray(x).astype(jnp.asarray(x).dtype), tree)


def abstract(tree, sharding):
    """``tree``'s shapes and dtypes placed as ``sharding`` says: what ``canonical`` makes of it, abstractly."""
    return jax.tree.map(lambda x: jax.ShapeDtypeStruct(x.shape, x.dtype, sharding=sharding), tree)
