"""The MLP's layers against flax's own: the same parameter tree, outputs and gradients, the per-feature
gradients summed in two stages."""

import functools

import flax.linen as nn
import jax
import jax.numpy as jnp
import numpy as np

from splid_jax.common.layers import row_blocks
from splid_jax.common.networks import MLP


class FlaxMLP(nn.Module):
    """The MLP written with flax's Dense and LayerNorm."""

    hidden: tuple
    action_size: int

    @nn.compact
    def __call__(self, x):
        for width in self.hidden:
            x = nn.relu(nn.LayerNorm()(nn.Dense(width, kernel_init=nn.initializers.orthogonal(jnp.sqrt(2.0)))(x)))
        return nn.Dense(self.action_size, kernel_init=nn.initializers.orthogonal(0.01))(x)


def test_row_blocks_is_the_largest_divisor_up_to_the_square_root():
    assert [row_blocks(n) for n in (1, 7, 12, 1024, 2000)] == [1, 1, 3, 32, 40]


def test_mlp_has_flax_layers_parameters_outputs_and_gradients():
    ours, theirs = MLP((16, 16), 3, activation="relu", layer_norm=True), FlaxMLP((16, 16), 3)
    x = jax.random.normal(jax.random.PRNGKey(0), (4, 60, 5))  # 4 vmapped members of 60 rows
    params = jax.jit(ours.init)(jax.random.PRNGKey(1), x[0])
    reference = jax.jit(theirs.init)(jax.random.PRNGKey(1), x[0])
    assert jax.tree_util.tree_structure(params) == jax.tree_util.tree_structure(reference)
    for a, b in zip(jax.tree_util.tree_leaves(params), jax.tree_util.tree_leaves(reference), strict=True):
        np.testing.assert_array_equal(a, b)
    # the parameters moved off their initial values, so every per-feature parameter shapes the output
    params = jax.tree_util.tree_map(lambda p: p + 0.1 * jax.random.normal(jax.random.PRNGKey(2), p.shape), params)

    def loss(net, p, xs):
        return jnp.sum(jnp.sin(net.apply(p, xs)))

    @functools.partial(jax.jit, static_argnums=0)  # one program per network, not an operation at a time
    def grads_and_outputs(net, p, xs):
        return jax.vmap(jax.grad(lambda p, xs: loss(net, p, xs)), in_axes=(None, 0))(p, xs), net.apply(p, xs)

    ours_grad, ours_out = grads_and_outputs(ours, params, x)
    theirs_grad, theirs_out = grads_and_outputs(theirs, params, x)
    np.testing.assert_allclose(ours_out, theirs_out, rtol=1e-5, atol=1e-6)
    for a, b in zip(jax.tree_util.tree_leaves(ours_grad), jax.tree_util.tree_leaves(theirs_grad), strict=True):
        np.testing.assert_allclose(a, b, rtol=1e-4, atol=1e-5)
