"""Exploration noise: the fingers' draws held for several steps while the arm's stay fresh."""

import jax
import jax.numpy as jnp
import numpy as np

from splid_jax.learners.imitation.explore import hold_fingers


def test_the_fingers_noise_is_held_and_the_arms_is_not():
    noise = jax.random.normal(jax.random.PRNGKey(0), (10, 3, 4))
    held = np.asarray(jax.jit(hold_fingers)(noise, jnp.int32(4)))
    np.testing.assert_array_equal(held[..., :3], noise[..., :3])
    for t in range(10):
        np.testing.assert_array_equal(held[t, :, 3], noise[t - t % 4, :, 3])  # drawn at 0, 4 and 8
    np.testing.assert_array_equal(hold_fingers(noise, jnp.int32(1)), noise)  # 1: every step afresh
