import chex
import jax
import jax.numpy as jnp
import optax

from splid_jax import relabel_buffer
from splid_jax.bc import bc_epoch, bc_loss, bc_step
from splid_jax.networks import make_policy


def _setup():
    policy = make_policy(2, 2, 2, (32, 32), normalise=False)
    pstate = policy.init(jax.random.PRNGKey(0))
    k1, k2 = jax.random.split(jax.random.PRNGKey(1))
    obs, goal = jax.random.normal(k1, (64, 2)), jax.random.normal(k2, (64, 2))
    action = jnp.clip(goal - obs, -1, 1)  # a learnable target
    return policy, pstate, (obs, goal, action)


def test_bc_steps_on_a_fixed_batch_lower_the_loss():
    policy, pstate, batch = _setup()
    opt = optax.adam(1e-2)
    opt_state = opt.init(pstate.params)
    before = bc_loss(pstate.params, policy, pstate, *batch)
    step = jax.jit(lambda p, o: bc_step(policy, opt, p, o, batch, 1.0))
    for _ in range(100):
        pstate, opt_state, _ = step(pstate, opt_state)
    after = bc_loss(pstate.params, policy, pstate, *batch)
    assert float(after) < 0.2 * float(before)


def test_empty_buffer_leaves_parameters_unchanged():
    policy, pstate, _ = _setup()
    opt = optax.adam(1e-2)
    buf = relabel_buffer.init(16, 2, 2, 2)
    new, _, _ = bc_epoch(policy, opt, pstate, opt.init(pstate.params), buf, jax.random.PRNGKey(0), 5, 8)
    chex.assert_trees_all_equal(new.params, pstate.params)


def test_normaliser_ignores_rows_flagged_invalid():
    policy = make_policy(2, 2, 2, (8,), normalise=True)
    pstate = policy.init(jax.random.PRNGKey(0))
    obs = jnp.array([[1.0, 2.0], [jnp.nan, jnp.nan], [3.0, 4.0]])
    goal = jnp.zeros((3, 2))
    new = policy.update_normaliser(pstate, obs, goal, jnp.array([True, False, True]))
    clean = policy.update_normaliser(pstate, obs[jnp.array([0, 2])], goal[:2])
    chex.assert_trees_all_close(new.normaliser.mean, clean.normaliser.mean)
    chex.assert_trees_all_close(new.normaliser.std, clean.normaliser.std)
    assert bool(jnp.all(jnp.isfinite(policy.act(new, obs[:1], goal[:1]))))
