"""The physics backend choice: a task's ``physics`` field, recorded when chosen, and the version guard that runs
stock MJX, saying so once, on a MuJoCo the kernels were not checked on."""

from __future__ import annotations

import jax
import pytest

import envs
from envs import mjx_patch, physics
from envs.settings import InvalidConfig
from tests.helpers import needs_kernels


def _step_jaxpr(env) -> str:
    """``env``'s step of one env as traced: its program before any compile."""
    state = jax.eval_shape(env.reset, jax.random.PRNGKey(0))
    return str(jax.make_jaxpr(env.step)(state, jax.ShapeDtypeStruct((env.action_size,), "float32")))


@pytest.fixture(scope="module")
def stock():
    return _step_jaxpr(envs.make("reach", substeps=1, physics="mjx"))


@needs_kernels
def test_the_kernels_run_on_the_checked_version(stock):
    env = envs.make("reach", substeps=1)
    assert physics.installed() == (physics.KERNELS_CHECKED, physics.KERNELS_CHECKED)
    assert env.physics == "kernels" and env.physics_in_use() == "kernels"
    kernels = _step_jaxpr(env)
    assert "cholesky" in stock and "cholesky" not in kernels  # MJX's library Cholesky, or the unrolled one


def test_another_mujoco_runs_stock_mjx_with_a_one_line_notice(monkeypatch, capsys, stock):
    monkeypatch.setattr(physics, "KERNELS_CHECKED", "0.0.0")

    def refused(**_):
        raise AssertionError("MJX patched on a version the kernels were not checked on")

    monkeypatch.setattr(mjx_patch, "patched_mjx", refused)
    env = envs.make("reach", substeps=1)
    assert env.physics_in_use() == "mjx"
    assert _step_jaxpr(env) == stock
    assert _step_jaxpr(env) == stock
    notice = capsys.readouterr().err.strip().splitlines()
    assert len(notice) == 1 and "physics=mjx" in notice[0] and physics.installed()[0] in notice[0]
    assert "0.0.0" in notice[0]


def test_the_choice_is_checked_and_recorded_when_not_the_default():
    assert "physics" not in envs.make("push").settings()  # runs recorded before the choice still match
    assert envs.make("push", physics="mjx").settings()["physics"] == "mjx"
    with pytest.raises(InvalidConfig, match="push.physics"):
        envs.make("push", physics="warp")
    error = RuntimeError("INTERNAL: Triton compilation failed")
    assert envs.make("push").kernel_fallback(error) and envs.make("push", physics="mjx").kernel_fallback(error) is None
