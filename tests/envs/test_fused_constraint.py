"""The constraint-row kernel: MJX's rows to float rounding on Push's and Slide's states with contacts (its program run
with XLA here), MJX's own for models it does not cover, one Triton call in a step lowered for a GPU."""

from __future__ import annotations

import jax
import numpy as np
import pytest
from mujoco import mjx

import envs
from envs import fused_constraint
from envs.base import data_with
from envs.fetch.scripted import CONTROLLERS
from tests.helpers import triton_calls_in_step


def _rows(env, physics, mode: str):
    """The constraint rows MJX's forward dynamics make for one env: MJX's, this module's function, or its kernel's
    program run by XLA."""
    model = env.mjx_model
    data = data_with(mjx.make_data(model), physics)
    with fused_constraint.fused_in_mjx(mode != "mjx", kernel=mode == "kernel", interpret=True):
        impl = mjx.forward(model, data)._impl
    return impl.efc_J, impl.efc_D, impl.efc_aref, impl.efc_pos, impl.efc_margin, impl.efc_frictionloss


@pytest.mark.parametrize("task", ["push", "slide"])
def test_rows_are_mjxs_on_scripted_states(task):
    env = envs.make(task, solver_loops="loops")
    state = jax.jit(jax.vmap(env.reset))(jax.random.split(jax.random.PRNGKey(0), 4))
    act, step = jax.jit(jax.vmap(CONTROLLERS[env.kind])), jax.jit(jax.vmap(env.step))
    for _ in range(8):  # the fingers reach the object
        state = step(state, act(state.obs, state.desired_goal))
    want = jax.jit(jax.vmap(lambda p: _rows(env, p, "mjx")))(state.physics)
    assert int((np.asarray(want[3]) < 0).sum()) > 0  # rows in contact
    got = jax.jit(jax.vmap(lambda p: _rows(env, p, "kernel")))(state.physics)  # the kernel's body is the function
    for g, w in zip(got, want, strict=True):
        np.testing.assert_allclose(g, w, rtol=1e-5, atol=1e-6 * (float(np.abs(w).max()) + 1e-9))


def test_models_with_other_rows_keep_mjxs():
    env = envs.make("pick_and_place")  # its fingers' joint limits make limit rows
    assert fused_constraint.layout(env.mjx_model, mjx.make_data(env.mjx_model)) is None
    push = envs.make("push").mjx_model
    assert fused_constraint.layout(push, mjx.make_data(push)).nefc == 56  # 8 contacts of 4 rows, 4 of 6


def test_push_makes_its_rows_in_a_kernel_on_a_gpu_when_asked(monkeypatch):
    env = envs.make("push", substeps=1, constraint="gpu-fused")
    assert triton_calls_in_step(env, monkeypatch) == (0, 4)  # the default's three and the rows
    assert "constraint=mjx" in env.kernel_fallback(RuntimeError("Triton compilation failed"))
