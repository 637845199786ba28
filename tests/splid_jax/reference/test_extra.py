"""The optional extra: the run-time fix of gymnasium-robotics' joint getters, applied only where they
fail, and a Fetch*-v4 made and stepped with it."""

import importlib.util

import numpy as np
import pytest

pytest.importorskip("gymnasium_robotics")

from splid_jax.reference import extra  # noqa: E402


def fresh_mujoco_utils():
    """An unpatched copy of gymnasium-robotics' ``utils/mujoco_utils.py``."""
    import gymnasium_robotics.utils.mujoco_utils as mu

    spec = importlib.util.spec_from_file_location("mujoco_utils_copy", mu.__file__)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_fix_is_applied_only_where_the_getters_fail():
    import mujoco

    mu = fresh_mujoco_utils()
    fails = extra.joint_getters_fail(mu)
    newer = tuple(int(x) for x in mujoco.__version__.split(".")[:2]) >= (3, 12)
    assert fails == newer
    assert extra.fix_joint_type_asserts(mu) == fails
    assert not extra.joint_getters_fail(mu)
    assert extra.fix_joint_type_asserts(mu) is False  # applied once


def test_fixed_getters_read_and_write_each_joint_type():
    import mujoco

    xml = """<mujoco><worldbody>
      <body><joint name="f" type="free"/><geom size="0.1"/></body>
      <body><joint name="b" type="ball"/><geom size="0.1"/></body>
      <body><joint name="s" type="slide"/><joint name="h" type="hinge"/><geom size="0.1"/></body>
    </worldbody></mujoco>"""
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    mu = fresh_mujoco_utils()
    extra.fix_joint_type_asserts(mu)
    for name, nq, nv in (("f", 7, 6), ("b", 4, 3), ("s", 1, 1), ("h", 1, 1)):
        mu.set_joint_qpos(m, d, name, np.arange(nq) + 1.0)
        mu.set_joint_qvel(m, d, name, np.arange(nv) + 2.0)
        np.testing.assert_array_equal(mu.get_joint_qpos(m, d, name), np.arange(nq) + 1.0)
        np.testing.assert_array_equal(mu.get_joint_qvel(m, d, name), np.arange(nv) + 2.0)


def test_fetch_push_resets_and_steps_with_the_fix():
    env = extra.make_reference("push")
    obs, _ = env.reset(seed=0)
    assert obs["observation"].shape == (25,) and obs["desired_goal"].shape == (3,)
    obs, *_ = env.step(np.zeros(4))
    env.close()


def test_slide_on_a_mujoco_after_the_unpatched_release_is_noted():
    assert "3.17.0" in extra.release_notice("slide", "3.17.0") and "3.11.0" in extra.release_notice("slide", "3.17.0")
    assert extra.release_notice("slide", "3.11.0") is None and extra.release_notice("slide", "3.4.0") is None
    assert extra.release_notice("push", "3.17.0") is None and extra.release_notice("slide", "3.12.1") is not None
