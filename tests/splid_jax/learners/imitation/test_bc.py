import chex
import jax
import jax.numpy as jnp
import optax

from splid_jax.common.networks import make_policy
from splid_jax.learners.imitation import relabel_buffer
from splid_jax.learners.imitation.bc import bc_epoch, bc_loss, bc_step


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
        pstate, opt_state, _, _ = step(pstate, opt_state)
    after = bc_loss(pstate.params, policy, pstate, *batch)
    assert float(after) < 0.2 * float(before)


def test_polyak_acting_policy_follows_the_cloned_one_at_its_step_one_minus_decay():
    policy, pstate, batch = _setup()
    opt = optax.adam(1e-2)
    opt_state = opt.init(pstate.params)
    online = jax.tree_util.tree_map(jnp.copy, pstate.params)
    step = jax.jit(lambda p, o, on: bc_step(policy, opt, p, o, batch, 1.0, on, acting_step=0.1))  # decay 0.9
    acting, _, cloned, _ = step(pstate, opt_state, online)
    # one step: the acting parameters move a tenth of the way the cloned ones moved
    moved = jax.tree_util.tree_map(lambda a, c, o: a - (o + 0.1 * (c - o)), acting.params, cloned, online)
    assert max(float(jnp.max(jnp.abs(x))) for x in jax.tree_util.tree_leaves(moved)) < 1e-6
    ps, os, on = pstate, opt_state, online
    for _ in range(200):
        ps, os, on, _ = step(ps, os, on)
    before = float(bc_loss(pstate.params, policy, pstate, *batch))
    assert float(bc_loss(on, policy, ps, *batch)) < 0.2 * before  # the cloned parameters learn
    assert float(bc_loss(ps.params, policy, ps, *batch)) < 0.2 * before  # and the average acts as well


def test_empty_buffer_leaves_parameters_unchanged():
    policy, pstate, _ = _setup()
    opt = optax.adam(1e-2)
    buf = relabel_buffer.init(16, 2, 2, 2)
    new, _, _, _ = bc_epoch(policy, opt, pstate, opt.init(pstate.params), buf, jax.random.PRNGKey(0), 5, 8)
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


def _filled_buffer(batch):
    buf = relabel_buffer.init(64, 2, 2, 2)
    return relabel_buffer.insert(buf, *batch, jnp.ones((64,), bool))


def test_an_epoch_of_active_steps_takes_those_steps_and_leaves_the_rest_as_no_ops():
    policy, pstate, batch = _setup()
    opt = optax.adam(1e-2)
    buf, key = _filled_buffer(batch), jax.random.PRNGKey(3)
    start = opt.init(pstate.params)
    epoch = jax.jit(lambda active: bc_epoch(policy, opt, pstate, start, buf, key, 6, 8, active=active))
    # every step active: the epoch without a count, bit for bit
    whole = bc_epoch(policy, opt, pstate, opt.init(pstate.params), buf, key, 6, 8)
    chex.assert_trees_all_equal(epoch(jnp.int32(6))[:2], whole[:2])
    # two active: the first two of the six steps' minibatches, and Adam counts two steps
    ps, os = pstate, opt.init(pstate.params)
    losses = []
    step = jax.jit(lambda ps, os, k: bc_step(policy, opt, ps, os, relabel_buffer.sample(buf, k, 8), 1.0))
    for k in jax.random.split(key, 6)[:2]:
        ps, os, _, loss = step(ps, os, k)
        losses.append(loss)
    two = epoch(jnp.int32(2))
    chex.assert_trees_all_close(two[0].params, ps.params, rtol=1e-6, atol=1e-7)
    assert int(two[1][0].count) == 2
    assert abs(float(two[3]) - float(jnp.mean(jnp.stack(losses)))) < 1e-6


def test_a_held_share_clones_the_held_pairs_that_much_more():
    """Every state seen twice, once held (zero action) and once moved (action 1): the held share sets what the
    policy learns to output there, the uniform draw the pairs' mean."""
    policy = make_policy(2, 2, 2, (32, 32), normalise=False)
    pstate = policy.init(jax.random.PRNGKey(0))
    obs = jax.random.normal(jax.random.PRNGKey(1), (32, 2))
    obs, goal = jnp.concatenate([obs, obs]), jnp.concatenate([obs, obs])
    action = jnp.concatenate([jnp.zeros((32, 2)), jnp.ones((32, 2))])
    buf = relabel_buffer.insert(relabel_buffer.init(64, 2, 2, 2), obs, goal, action, jnp.ones(64, bool))
    opt = optax.adam(3e-3)
    epoch = jax.jit(lambda share: bc_epoch(policy, opt, pstate, opt.init(pstate.params), buf, jax.random.PRNGKey(2),
                                           400, 32, held_share=share)[0])  # fmt: skip
    mean_action = lambda ps: float(jnp.mean(policy.mean(ps, obs[:32], goal[:32])))  # noqa: E731
    assert abs(mean_action(epoch(0.0)) - 0.5) < 0.1
    assert abs(mean_action(epoch(0.6)) - 0.2) < 0.1  # 0.6 + 0.4 / 2 of the draws held
