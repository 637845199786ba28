import jax
import jax.numpy as jnp
import numpy as np
import optax

from splid_jax.common.networks import STD_MIN, make_policy
from splid_jax.learners.imitation.bc import bc_step

OBS, GOAL = 3, 2  # obs: a point's x, y and a locked finger's position, which never varies in training


def _data(key, n):
    k1, k2 = jax.random.split(key)
    pos = jax.random.uniform(k1, (n, 2), minval=-5, maxval=5)
    goal = jax.random.uniform(k2, (n, GOAL), minval=-5, maxval=5)
    obs = jnp.concatenate([pos, jnp.full((n, 1), 0.04)], axis=-1)  # the finger rests at 0.04
    return obs, goal, jnp.clip(goal - pos, -1, 1)


def _trained_policy():
    """A policy cloned for 300 steps onto the point task's greedy action, its normaliser fitted to the data."""
    policy = make_policy(OBS, GOAL, 2, (64, 64), normalise=True)
    obs, goal, action = _data(jax.random.PRNGKey(0), 2048)
    pstate = policy.update_normaliser(policy.init(jax.random.PRNGKey(1)), obs, goal)
    opt = optax.adam(1e-3)

    def step(carry, idx):
        ps, os_ = carry
        ps, os_, _, loss = bc_step(policy, opt, ps, os_, (obs[idx], goal[idx], action[idx]), 1.0)
        return (ps, os_), loss

    batches = jax.random.randint(jax.random.PRNGKey(2), (300, 128), 0, obs.shape[0])
    (pstate, _), losses = jax.jit(lambda ps: jax.lax.scan(step, (ps, opt.init(ps.params)), batches))(pstate)
    return policy, pstate, losses


def test_normaliser_std_has_a_floor_for_inputs_that_never_vary():
    policy, pstate, _ = _trained_policy()
    std = np.asarray(pstate.normaliser.std)
    assert std[OBS - 1] == np.float32(STD_MIN)  # the finger's entry
    assert std[:2].min() > 1  # the positions keep their own spread


def test_trained_policy_barely_moves_under_a_small_offset_of_any_input():
    policy, pstate, losses = _trained_policy()
    assert float(losses[-10:].mean()) < 0.5 * float(losses[:10].mean())  # it did learn
    obs, goal, _ = _data(jax.random.PRNGKey(3), 256)
    act = jax.jit(policy.act)
    base = act(pstate, obs, goal)
    worst = 0.0
    for i in range(OBS + GOAL):  # a real Fetch's fingers are never exactly still: 1e-3 on each input in turn
        for sign in (1.0, -1.0):
            x = jnp.concatenate([obs, goal], axis=-1).at[:, i].add(sign * 1e-3)
            worst = max(worst, float(jnp.abs(act(pstate, x[:, :OBS], x[:, OBS:]) - base).max()))
    # The finger's 1e-3 is 0.1 std under the floor; its first-layer weights never trained, so it moves
    # the action by about 0.05 (without the floor: 1e-3 / 1e-6 hits the clip of 5 std, and 1.4).
    assert worst < 0.1, worst


def test_relative_goal_input_is_the_goal_minus_the_achieved_goal_in_success_units():
    policy = make_policy(5, 2, 2, (8,), normalise=False, achieved_start=1, goal_unit=0.05)
    obs = jnp.asarray([[9.0, 1.0, 2.0, 7.0, 8.0]])
    goal = jnp.asarray([[1.1, 1.5]])
    np.testing.assert_allclose(policy.features(obs, goal)[0, -2:], [2.0, -10.0], rtol=1e-5)
    assert policy.in_size == 5 + 2 + 2
    pstate = policy.init(jax.random.PRNGKey(0))
    assert policy.act(pstate, obs, goal).shape == (1, 2)
    # the same obs and goal moved together leave the relative input as it was
    np.testing.assert_allclose(policy.features(obs.at[:, 1:3].add(0.3), goal + 0.3)[0, -2:], [2.0, -10.0], rtol=1e-4)
