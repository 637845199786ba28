import chex
import jax
import jax.numpy as jnp
import numpy as np
import pytest

import envs
from splid_jax.common.errors import InvalidConfig


@pytest.fixture(scope="module")
def env():
    return envs.make("point")


def test_contract_shapes(env):
    states = jax.vmap(env.reset)(jax.random.split(jax.random.PRNGKey(0), 4))
    chex.assert_shape([states.obs, states.achieved_goal, states.desired_goal], (4, 2))
    nxt = jax.vmap(env.step)(states, jnp.ones((4, 2)))
    chex.assert_shape(nxt.obs, (4, 2))
    chex.assert_trees_all_equal(nxt.step, jnp.ones(4, jnp.int32))
    assert env.episode_length == 50 and env.action_size == 2


def test_resets_never_start_inside_a_wall(env):
    states = jax.vmap(env.reset)(jax.random.split(jax.random.PRNGKey(1), 4096))
    assert not bool(jnp.any(env.in_wall(states.obs)))
    assert not bool(jnp.any(env.in_wall(states.desired_goal)))
    assert float(jnp.max(jnp.abs(states.obs))) <= 5.0


def test_walls_block_and_doorways_pass(env):
    s = env.reset(jax.random.PRNGKey(0))
    blocked = s.replace(physics=jnp.array([-3.0, 1.0]))  # y = 1 is wall on the vertical arm
    through = s.replace(physics=jnp.array([-3.0, 2.5]))  # y = 2.5 is the doorway's centre
    for _ in range(6):
        blocked = env.step(blocked, jnp.array([1.0, 0.0]))
        through = env.step(through, jnp.array([1.0, 0.0]))
    np.testing.assert_allclose(blocked.obs, [-env.wall_half_width, 1.0])
    np.testing.assert_allclose(through.obs, [3.0, 2.5])


def test_random_walk_never_enters_walls_or_leaves_the_box(env):
    def walk(key):
        k0, k1 = jax.random.split(key)
        s = env.reset(k0)

        def one(s, k):
            s = env.step(s, jax.random.uniform(k, (2,), minval=-1.5, maxval=1.5))
            return s, s.obs

        return jax.lax.scan(one, s, jax.random.split(k1, 200))[1]

    path = jax.jit(jax.vmap(walk))(jax.random.split(jax.random.PRNGKey(3), 64))
    assert not bool(jnp.any(env.in_wall(path)))
    assert float(jnp.max(jnp.abs(path))) <= 5.0


def test_success_uses_unit_radius_and_reward_is_binary(env):
    assert bool(env.success(jnp.array([0.0, 0.0]), jnp.array([0.6, 0.79])))
    assert not bool(env.success(jnp.array([0.0, 0.0]), jnp.array([0.8, 0.8])))
    s = env.with_goal(env.reset(jax.random.PRNGKey(0)), jnp.zeros(2))
    s = s.replace(physics=jnp.array([-3.0, -3.0]))
    assert float(env.step(s, jnp.zeros(2)).reward) == 0.0


def test_nan_action_is_flagged(env):
    s = env.step(env.reset(jax.random.PRNGKey(0)), jnp.array([jnp.nan, 0.0]))
    assert bool(s.invalid)


@pytest.mark.parametrize(
    "field,value", [("success_radius", 0.0), ("max_episode_steps", 1), ("wall_half_width", -1.0), ("nope", 1)]
)
def test_bad_overrides_name_the_field(field, value):
    with pytest.raises(InvalidConfig, match=field):
        envs.make("point", **{field: value})


def test_unknown_env_lists_known_names():
    with pytest.raises(InvalidConfig, match="point, reach, push"):
        envs.make("fourrooms")
