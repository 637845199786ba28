"""Stage 3 of Algorithm 2: behaviour cloning, an optax step on the MSE to the stored action."""

from __future__ import annotations

import jax
import jax.numpy as jnp
import optax

from splid_jax import relabel_buffer
from splid_jax.networks import Policy, PolicyState


def bc_loss(params, policy: Policy, pstate: PolicyState, obs, goal, action) -> jax.Array:
    pred = policy.mean(pstate, obs, goal, params=params)
    return jnp.mean(jnp.sum((pred - action) ** 2, axis=-1))


def bc_step(policy: Policy, optimiser: optax.GradientTransformation, pstate: PolicyState, opt_state, batch, weight):
    """One gradient step; ``weight`` = 0 turns it into a no-op (empty buffer) with static shapes."""
    loss, grads = jax.value_and_grad(bc_loss)(pstate.params, policy, pstate, *batch)
    grads = jax.tree_util.tree_map(lambda g: g * weight, grads)
    updates, new_opt = optimiser.update(grads, opt_state, pstate.params)
    new_params = optax.apply_updates(pstate.params, updates)
    keep = weight > 0
    new_params = jax.tree_util.tree_map(lambda n, o: jnp.where(keep, n, o), new_params, pstate.params)
    new_opt = jax.tree_util.tree_map(lambda n, o: jnp.where(keep, n, o), new_opt, opt_state)
    return pstate.replace(params=new_params), new_opt, loss


def bc_epoch(policy, optimiser, pstate, opt_state, buf: relabel_buffer.Buffer, key, num_steps: int, batch_size: int):
    """``num_steps`` minibatch steps from the buffer; returns the mean loss."""
    weight = (buf.size > 0).astype(jnp.float32)

    def one(carry, k):
        ps, os = carry
        batch = relabel_buffer.sample(buf, k, batch_size)
        ps, os, loss = bc_step(policy, optimiser, ps, os, batch, weight)
        return (ps, os), loss

    (pstate, opt_state), losses = jax.lax.scan(one, (pstate, opt_state), jax.random.split(key, num_steps))
    return pstate, opt_state, jnp.mean(losses)
