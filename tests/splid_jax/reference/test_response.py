"""The physical-response measurements move the gripper and the cube in both simulators."""

import numpy as np
import pytest

pytest.importorskip("gymnasium_robotics")

from envs import make as make_env  # noqa: E402
from splid_jax.reference import response  # noqa: E402


@pytest.mark.slow
def test_response_measurements_move_the_gripper_and_the_cube_in_both_simulators():
    env = make_env("push", cholesky="library")  # the same physics to float rounding; its step compiles faster
    resp = response.step_response(env, "push", hold=2, release=1)
    assert np.asarray(resp["ours_step"]).shape == np.asarray(resp["fetch_rest_step"]).shape == (3, 3)
    assert resp["ours_step"][1][0] > 0.02 and resp["fetch_step"][1][0] > 0.02  # a_x = 1: tens of mm per step
    slide = response.cube_slide(env, "push", (0.5, 0.0), steps=3)
    assert slide["ours_travel"] > 0.005 and slide["fetch_travel"] > 0.005
    push = response.loaded_push(env, "push", (0.0, 1.0, 0.0, 0.0), hold=3, release=1)
    assert sum(push["ours_object_step"]) > 0.02 and sum(push["fetch_object_step"]) > 0.02
