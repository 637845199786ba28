"""``step_batch``: the batched step that every stage uses."""

import subprocess
import sys
import textwrap

import chex
import jax
import pytest

import envs
from envs.base import CPU_STEP_SLICE, step_batch


def test_slices_give_what_one_vmap_gives():
    env = envs.make("point")
    n = 2 * CPU_STEP_SLICE + 37  # two whole slices and a remainder
    keys = jax.random.split(jax.random.PRNGKey(0), n)
    state = jax.vmap(env.reset)(keys)
    action = jax.random.uniform(jax.random.PRNGKey(1), (n, env.action_size), minval=-1.0, maxval=1.0)
    sliced = jax.jit(lambda s, a: step_batch(env, s, a))(state, action)
    whole = jax.jit(jax.vmap(env.step))(state, action)
    chex.assert_trees_all_close(sliced, whole, rtol=1e-6, atol=1e-6)


def test_a_cpu_computation_on_an_accelerator_host_is_sliced(monkeypatch, primitives):
    # a CPU peer on a GPU host: the default backend is the GPU, the default device the CPU
    env = envs.make("point")
    n = CPU_STEP_SLICE + 1
    state = jax.vmap(env.reset)(jax.random.split(jax.random.PRNGKey(0), n))
    action = jax.numpy.zeros((n, env.action_size))

    def prims():
        return primitives(lambda s, a: step_batch(env, s, a), state, action)

    monkeypatch.setattr(jax, "default_backend", lambda: "gpu")
    assert "scan" not in prims()  # on the accelerator: one vmap
    with jax.default_device(jax.devices("cpu")[0]):
        assert "scan" in prims()  # placed on the CPU: lax.map over slices


@pytest.mark.slow
def test_a_thousand_mjx_envs_step_on_the_cpu():
    # one vmap of this many MJX steps inside a loop never returned on a 2-core XLA:CPU; in a
    # subprocess so that a regression fails here instead of hanging the suite. Two whole slices: the
    # program holds one step (a remainder would add a second; test_slices_give_what_one_vmap_gives)
    code = textwrap.dedent(
        """
        import jax, envs
        from envs.base import CPU_STEP_SLICE, step_batch
        env, n = envs.make("push"), 2 * CPU_STEP_SLICE
        def run(key):
            s = jax.vmap(env.reset)(jax.random.split(key, n))
            def one(s, k):
                a = jax.random.uniform(k, (n, env.action_size), minval=-1.0, maxval=1.0)
                return step_batch(env, s, a), None
            return jax.lax.scan(one, s, jax.random.split(key, 3))[0].obs
        print(bool(jax.numpy.isfinite(jax.jit(run)(jax.random.PRNGKey(0))).all()))
        """
    )
    try:
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    except subprocess.TimeoutExpired as e:
        raise AssertionError("stepping 1,024 Push envs on the CPU did not finish in 300 s") from e
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.strip().splitlines()[-1] == "True"
