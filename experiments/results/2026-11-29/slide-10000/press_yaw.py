"""The centre and rim presses of ``experiments/reference/slide_on_puck.py`` in FetchSlide-v4 with the puck first
turned about its axis: whether the reference's slip-off at the rim and its puck's sideways exit depend on the puck's
yaw (its native collider meets the cap on a polygon that turns with the puck).

    PYTHONPATH=. python experiments/results/2026-11-29/slide-10000/press_yaw.py

Prints per press offset and yaw the grip's height above the puck's centre after the press (step 9) and the puck's x
and y move by the probe's end, from its placed position.
"""

from __future__ import annotations

import os
import sys

import mujoco
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "..", ".."))
sys.path.insert(1, os.path.join(HERE, "..", "..", "..", "reference"))

import slide_on_puck as probe  # noqa: E402

import envs  # noqa: E402
from splid_jax.reference.extra import import_reference, make_reference  # noqa: E402


def turn_puck(m, d, yaw_degrees: float) -> int:
    """FetchSlide-v4's puck turned to ``yaw_degrees`` about its axis from the identity (positions not recomputed);
    the address of its free joint in ``qpos``."""
    q = m.jnt_qposadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, "object0:joint")]
    half = np.radians(yaw_degrees) / 2
    d.qpos[q + 3 : q + 7] = [np.cos(half), 0.0, 0.0, np.sin(half)]
    return q


def press(task, offset: float, yaw_degrees: float) -> tuple[float, float, float]:
    env = make_reference("slide")
    probe.place_puck(task, env, probe.pressed_puck(offset))
    m, d = env.unwrapped.model, env.unwrapped.data
    q = turn_puck(m, d, yaw_degrees)
    mujoco.mj_forward(m, d)
    start = d.qpos[q : q + 2].copy()
    trace = np.array([env.step(np.asarray(a, np.float64))[0]["observation"][:6] for a in probe.ACTIONS])
    env.close()
    return trace[9, 2] - trace[9, 5], trace[-1, 3] - start[0], trace[-1, 4] - start[1]


def main() -> int:
    import_reference()
    task = envs.make("slide")
    for offset in (0.0, 0.02):
        for yaw in (0, 10, 22.5, 45, 90, 180):
            height, dx, dy = press(task, offset, yaw)
            print(f"off {offset} yaw {yaw:5.1f}: pressed height {height:+.4f}  puck x {dx:+.3f} y {dy:+.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
