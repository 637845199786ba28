"""The one FIFO ring insert every replay buffer uses: rows of a fixed-size batch, kept where a mask
holds, so shapes stay static under jit however many rows are kept."""

from __future__ import annotations

import jax
import jax.numpy as jnp


def insert(buf, rows: dict[str, jax.Array], mask: jax.Array):
    """``buf`` (a struct with ``ptr``, ``size`` and arrays of leading axis ``capacity``) with the rows of
    ``rows`` (one batch per array field, by name) appended where ``mask`` holds, in order; past capacity
    the oldest are overwritten, and of a batch larger than the capacity only its newest rows are kept."""
    cap = buf.capacity
    mask = mask.astype(bool)
    n = jnp.sum(mask, dtype=jnp.int32)
    rank = jnp.cumsum(mask, dtype=jnp.int32) - 1
    skip = jnp.maximum(n - cap, 0)
    slot = jnp.where(mask & (rank >= skip), (buf.ptr + rank - skip) % cap, cap)  # slot == cap is dropped
    written = {name: getattr(buf, name).at[slot].set(new, mode="drop") for name, new in rows.items()}
    return buf.replace(**written, ptr=(buf.ptr + jnp.minimum(n, cap)) % cap, size=jnp.minimum(buf.size + n, cap))
