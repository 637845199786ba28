"""Stage 3 of Algorithm 2: behaviour cloning, an optax step on the MSE to the stored action."""

from __future__ import annotations

import jax
import jax.numpy as jnp
import optax

from splid_jax.common.networks import Policy, PolicyState
from splid_jax.learners.imitation import relabel_buffer


def bc_loss(params, policy: Policy, pstate: PolicyState, obs, goal, action) -> jax.Array:
    pred = policy.mean(pstate, obs, goal, params=params)
    return jnp.mean(jnp.sum((pred - action) ** 2, axis=-1))


def bc_step(
    policy: Policy,
    optimiser: optax.GradientTransformation,
    pstate: PolicyState,
    opt_state,
    batch,
    weight,
    online=None,
    acting_step: float | jax.Array = 1.0,
):
    """One gradient step; ``weight`` = 0 turns it into a no-op (empty buffer) with static shapes.

    ``online`` is None when the cloned parameters act themselves (``pstate.params``). Otherwise they
    are ``online``, and ``pstate.params`` follows them as a Polyak average with step ``acting_step``
    (1 - its decay): each step's minibatch noise on the noisy explored actions then averages out of
    the acting policy."""
    cloned = pstate.params if online is None else online
    loss, grads = jax.value_and_grad(bc_loss)(cloned, policy, pstate, *batch)
    grads = jax.tree_util.tree_map(lambda g: g * weight, grads)
    updates, new_opt = optimiser.update(grads, opt_state, cloned)
    new_cloned = optax.apply_updates(cloned, updates)
    unless_empty = lambda new, old: jax.tree_util.tree_map(lambda n, o: jnp.where(weight > 0, n, o), new, old)  # noqa: E731
    new_cloned, new_opt = unless_empty(new_cloned, cloned), unless_empty(new_opt, opt_state)
    if online is None:
        return pstate.replace(params=new_cloned), new_opt, None, loss
    acting = unless_empty(optax.incremental_update(new_cloned, pstate.params, acting_step), pstate.params)
    return pstate.replace(params=acting), new_opt, new_cloned, loss


def bc_epoch(
    policy,
    optimiser,
    pstate,
    opt_state,
    buf: relabel_buffer.Buffer,
    key,
    num_steps: int,
    batch_size: int,
    online=None,
    acting_step: float | jax.Array = 1.0,
    active: jax.Array | None = None,
    window: jax.Array | None = None,
    held_share: jax.Array | float | None = None,
):
    """``num_steps`` minibatch steps from the buffer; returns (pstate, opt_state, online, mean loss).
    With ``active`` ([] int, traced) only the first ``active`` steps update: the rest are no-ops, so the shapes
    stay static and each step draws the minibatch it draws with all steps taken. ``window``: batches come
    from the newest ``window`` pairs (``relabel_buffer.sample``). ``held_share``: that share of each batch comes
    from the window's zero-action (held) pairs (``relabel_buffer.held_slots``)."""
    weight = (buf.size > 0).astype(jnp.float32)
    held = None if held_share is None else relabel_buffer.held_slots(buf, window)
    taken = jnp.ones((num_steps,), bool) if active is None else jnp.arange(num_steps) < active

    def one(carry, step):
        ps, os, on = carry
        k, take = step
        batch = relabel_buffer.sample(buf, k, batch_size, window, held, held_share)
        ps, os, on, loss = bc_step(policy, optimiser, ps, os, batch, weight * take, on, acting_step)
        return (ps, os, on), loss

    (pstate, opt_state, online), losses = jax.lax.scan(
        one, (pstate, opt_state, online), (jax.random.split(key, num_steps), taken)
    )
    if active is None:
        return pstate, opt_state, online, jnp.mean(losses)
    some = jnp.sum(jnp.where(taken, losses, 0.0)) / jnp.maximum(active, 1)
    return pstate, opt_state, online, jnp.where(active >= num_steps, jnp.mean(losses), some)
