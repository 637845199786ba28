"""``step_batch``: the batched step that every stage uses; where a task's MJX model and data live."""


import chex
import jax
import jax.numpy as jnp
import numpy as np
import pytest

import envs
import envs.point_fourrooms
from envs.base import CPU_STEP_SLICE, make_data, put_model, step_batch


def test_slices_give_what_one_vmap_gives():
    env = envs.make("point")
    n = 2 * CPU_STEP_SLICE + 37  # two whole slices and a remainder
    keys = jax.random.split(jax.random.PRNGKey(0), n)
    state = jax.jit(jax.vmap(env.reset))(keys)
    action = jax.random.uniform(jax.random.PRNGKey(1), (n, env.action_size), minval=-1.0, maxval=1.0)
    sliced = jax.jit(lambda s, a: step_batch(env, s, a))(state, action)
    whole = jax.jit(jax.vmap(env.step))(state, action)
    chex.assert_trees_all_close(sliced, whole, rtol=1e-6, atol=1e-6)


def test_a_cpu_computation_on_an_accelerator_host_is_sliced(monkeypatch, primitives):
    # a CPU peer on a GPU host: the default backend is the GPU, the default device the CPU
    env = envs.make("point")
    n = CPU_STEP_SLICE + 1
    state = jax.eval_shape(jax.vmap(env.reset), jax.random.split(jax.random.PRNGKey(0), n))  # a trace's shapes
    action = jax.numpy.zeros((n, env.action_size))

    def prims():
        return primitives(lambda s, a: step_batch(env, s, a), state, action)

    monkeypatch.setattr(jax, "default_backend", lambda: "gpu")
    assert "scan" not in prims()  # on the accelerator: one vmap
    with jax.default_device(jax.devices("cpu")[0]):
        assert "scan" in prims()  # placed on the CPU: lax.map over slices




@pytest.mark.parametrize("name", envs.names())
def test_the_achieved_goal_sits_where_the_task_says_and_success_ends_at_its_distance(name):
    env = envs.make(name)
    s = jax.jit(jax.vmap(env.reset))(jax.random.split(jax.random.PRNGKey(0), 4))
    start = env.achieved_goal_start
    np.testing.assert_array_equal(s.obs[:, start : start + env.goal_size], s.achieved_goal)
    direction = jnp.zeros(env.goal_size).at[0].set(1.0)
    inside = s.achieved_goal + 0.99 * env.success_distance * direction
    outside = s.achieved_goal + 1.01 * env.success_distance * direction
    assert bool(env.success(s.achieved_goal, inside).all()) and not bool(env.success(s.achieved_goal, outside).any())


class _CountedPoint(envs.point_fourrooms.PointFourRooms):
    """The point task, counting how often JAX traces its step (a Python side effect at trace time)."""

    def step(self, state, action):
        _TRACES.append(action.shape)
        return super().step(state, action)


_TRACES: list = []


def test_each_task_step_is_traced_once_whatever_the_batch_sizes():
    env = _CountedPoint()
    equal = _CountedPoint()  # another object, the same task: the same trace
    for task, n in ((env, 3), (env, 5), (equal, 7)):  # exploration, evaluation, SELECT: their own batch sizes
        state = jax.eval_shape(jax.vmap(task.reset), jax.random.split(jax.random.PRNGKey(0), n))
        jax.make_jaxpr(lambda s, a, task=task: step_batch(task, s, a))(state, jnp.zeros((n, task.action_size)))
    assert _TRACES == [(env.action_size,)]  # the unbatched step, once


def test_a_sliced_batch_holds_one_batched_step_however_many_envs():
    env = _CountedPoint()
    for n in (2 * CPU_STEP_SLICE, 2 * CPU_STEP_SLICE + 37):  # equal slices, and a batch padded to them
        state = jax.eval_shape(jax.vmap(env.reset), jax.random.split(jax.random.PRNGKey(0), n))
        with jax.default_device(jax.devices("cpu")[0]):
            jaxpr = jax.make_jaxpr(lambda s, a: step_batch(env, s, a))(state, jnp.zeros((n, env.action_size)))
        names = [e.primitive.name for e in jaxpr.jaxpr.eqns]
        # the slices' scan holds the batched step; a remainder would call it once more beside the scan
        assert names.count("scan") == 1 and not {"jit", "pjit"} & set(names), (n, names)


def test_an_mjx_model_and_its_data_live_on_this_processs_own_device(monkeypatch):
    """Under ``jax.distributed`` ``jax.devices()[0]``, MJX's default, is process 0's device, which another
    process can neither read nor close over in its programs."""
    import mujoco

    xml = "<mujoco><worldbody><body><joint type='slide'/><geom size='0.1'/></body></worldbody></mujoco>"
    model = mujoco.MjModel.from_xml_string(xml)
    monkeypatch.setattr(jax, "devices", lambda *a, **k: pytest.fail("placed on jax.devices()'s device"))
    placed = put_model(model, impl="jax")
    arrays = [x for x in jax.tree.leaves((placed, make_data(placed))) if isinstance(x, jax.Array)]
    assert arrays and all(x.devices() == {jax.local_devices()[0]} for x in arrays)
