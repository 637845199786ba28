import chex
import jax
import jax.numpy as jnp
import numpy as np

from splid_jax.learners.imitation import relabel_buffer


def _rows(values):
    v = jnp.asarray(values, jnp.float32)[:, None]
    return v, v + 100, v + 200


def test_masked_insert_keeps_only_masked_rows_in_order():
    buf = relabel_buffer.init(8, 1, 1, 1)
    obs, goal, act = _rows([1, 2, 3, 4, 5])
    buf = relabel_buffer.insert(buf, obs, goal, act, jnp.array([1, 0, 1, 0, 1], bool))
    assert int(buf.size) == 3 and int(buf.ptr) == 3
    np.testing.assert_array_equal(buf.obs[:3, 0], [1, 3, 5])
    np.testing.assert_array_equal(buf.goal[:3, 0], [101, 103, 105])
    np.testing.assert_array_equal(buf.obs[3:, 0], 0)


def test_wraps_around_overwriting_oldest():
    buf = relabel_buffer.init(4, 1, 1, 1)
    insert = jax.jit(relabel_buffer.insert)
    buf = insert(buf, *_rows([1, 2, 3]), jnp.ones(3, bool))
    buf = insert(buf, *_rows([4, 5, 6]), jnp.ones(3, bool))
    assert int(buf.size) == 4 and int(buf.ptr) == 2
    np.testing.assert_array_equal(buf.obs[:, 0], [5, 6, 3, 4])


def test_batch_larger_than_capacity_keeps_newest():
    buf = relabel_buffer.init(3, 1, 1, 1)
    buf = relabel_buffer.insert(buf, *_rows([1, 2, 3, 4, 5, 6]), jnp.array([1, 1, 1, 1, 1, 0], bool))
    assert int(buf.size) == 3
    assert sorted(np.asarray(buf.obs[:, 0]).tolist()) == [3, 4, 5]


def test_sampling_draws_only_filled_rows_uniformly():
    buf = relabel_buffer.init(100, 1, 1, 1)
    buf = relabel_buffer.insert(buf, *_rows([1, 2, 3, 4]), jnp.ones(4, bool))
    obs, goal, act = relabel_buffer.sample(buf, jax.random.PRNGKey(0), 4000)
    chex.assert_shape([obs, goal, act], (4000, 1))
    values, counts = np.unique(np.asarray(obs[:, 0]), return_counts=True)
    np.testing.assert_array_equal(values, [1, 2, 3, 4])
    assert counts.min() > 850  # about 1000 each
    np.testing.assert_array_equal(goal - obs, 100)  # rows stay aligned


def test_a_window_draws_the_newest_pairs_as_a_fifo_of_that_capacity_holds_them():
    buf = relabel_buffer.init(8, 1, 1, 1)
    buf = relabel_buffer.insert(buf, *_rows(np.arange(1, 12)), jnp.ones(11, bool))  # 4..11 kept, 9..11 newest
    obs, goal, _ = relabel_buffer.sample(buf, jax.random.PRNGKey(0), 3000, window=3)
    values, counts = np.unique(np.asarray(obs[:, 0]), return_counts=True)
    np.testing.assert_array_equal(values, [9, 10, 11])
    assert counts.min() > 850  # about 1000 each
    np.testing.assert_array_equal(goal - obs, 100)
    # a window holding every pair draws exactly the whole buffer's batch
    key = jax.random.PRNGKey(4)
    for window in (8, 100):
        chex.assert_trees_all_equal(
            relabel_buffer.sample(buf, key, 64, window=window), relabel_buffer.sample(buf, key, 64)
        )
    part = relabel_buffer.insert(relabel_buffer.init(8, 1, 1, 1), *_rows([1, 2]), jnp.ones(2, bool))
    chex.assert_trees_all_equal(relabel_buffer.sample(part, key, 64, window=3), relabel_buffer.sample(part, key, 64))


def test_a_held_share_draws_that_share_from_the_zero_action_pairs_in_the_window():
    buf = relabel_buffer.init(16, 1, 1, 1)
    obs = jnp.arange(1.0, 13.0)[:, None]
    action = jnp.where(jnp.isin(obs, jnp.array([2.0, 9.0, 11.0])), 0.0, 1.0)  # three held pairs
    buf = relabel_buffer.insert(buf, obs, obs + 100, action, jnp.ones(12, bool))
    key = jax.random.PRNGKey(3)
    held = relabel_buffer.held_slots(buf, window=6)  # the newest 6: 7..12, held 9 and 11
    assert int(held.count) == 2
    drawn, _, act = relabel_buffer.sample(buf, key, 4000, 6, held, 0.3)
    drawn = np.asarray(drawn[:, 0])
    assert set(np.unique(drawn)) <= set(range(7, 13))
    zero = np.isin(drawn, [9, 11])
    np.testing.assert_array_equal(np.asarray(act[:, 0]) == 0, zero)
    assert 0.3 + 2 / 6 * 0.7 - 0.04 < zero.mean() < 0.3 + 2 / 6 * 0.7 + 0.04
    # share 0 leaves the uniform batch exactly
    chex.assert_trees_all_equal(
        relabel_buffer.sample(buf, key, 64, 6, held, 0.0), relabel_buffer.sample(buf, key, 64, 6)
    )
    # no held pair in the window: the uniform batch
    none = relabel_buffer.held_slots(buf, window=1)
    assert int(none.count) == 0
    chex.assert_trees_all_equal(
        relabel_buffer.sample(buf, key, 64, 1, none, 0.5), relabel_buffer.sample(buf, key, 64, 1)
    )
