"""Slide's pads pitched out as the reference arm stretches (task field ``hand_pitch``).

FetchSlide-v4's hand hangs from a 7-joint arm on a mocap weld: as the grip nears the arm's reach its wrist can no
longer hold the hand upright, and the hand leans out with the arm, its fingertips swinging away from the robot, 2
degrees at 0.89 m from the reach centre, 11 at 0.96, 21 at 1.01, 54 at the reach's edge, whatever the speed or height
(``experiments/reference/hand_tilt.py``). Our gripper has no arm and stays upright, so a policy pressing the puck
keeps it there far out, where the reference's tilted pads let it go (experiments/NOTES.md, "The hand's pitch").

The pitch is kinematic: within the collision step the two pad boxes turn about their common centre (the reference
hand's origin, 2 cm above the grip site) by ``hand_pitch`` x the reference's tilt at the grip's reach, about the
horizontal axis across the radial direction; their contacts with the puck and the table are computed there and
act on the gripper as before. The gripper itself neither turns nor feels a torque, and a rendering shows the pads
upright. Carried by the model as a custom numeric, so a model's own contacts know it (``wrap``).
"""

from __future__ import annotations

import jax.numpy as jnp
import numpy as np

from envs.fetch.control import ARM_REACH_CENTER

NUMERIC = "hand_pitch"
PADS = ("pad_r", "pad_l")
# The reference hand's tilt (degrees, the median over 15 drives) against the grip's distance from the reach centre
# (m), MuJoCo 3.17.0 (3.11.0 alike): experiments/reference/results/hand-tilt.json. Upright below the first point.
REACH = (0.70, 0.7875, 0.8125, 0.8375, 0.8625, 0.8875, 0.9125, 0.9375, 0.9625, 0.9875, 1.0125, 1.0375, 1.0625, 1.0875,
         1.1125, 1.1375)  # fmt: skip
TILT = (0.0, 0.9, 0.9, 1.3, 1.5, 2.3, 3.6, 6.1, 11.0, 15.8, 21.2, 26.9, 33.8, 40.2, 51.2, 54.2)
GRIP_BELOW_HAND = 0.02  # the grip site below the pads' common centre (slide_fingers.PAD_CENTERS)


def rotation(hand: jnp.ndarray, scale, center=ARM_REACH_CENTER["slide"]) -> jnp.ndarray:
    """[3, 3] the pads' turn for a hand (the pads' common centre) at ``hand``: ``scale`` x the reference's tilt
    at the grip's reach, the bottom swinging out, away from the robot."""
    grip = hand - jnp.array([0.0, 0.0, GRIP_BELOW_HAND])
    off = grip - jnp.asarray(center)
    theta = jnp.deg2rad(scale * jnp.interp(jnp.linalg.norm(off), jnp.asarray(REACH), jnp.asarray(TILT)))
    radial = off[:2] / jnp.maximum(jnp.linalg.norm(off[:2]), 1e-9)
    k = jnp.array([[0.0, 0.0, -radial[0]], [0.0, 0.0, -radial[1]], [radial[0], radial[1], 0.0]])  # cross(axis, .)
    return jnp.eye(3) + jnp.sin(theta) * k + (1.0 - jnp.cos(theta)) * (k @ k)


def pitched(group, pads: tuple[int, ...], scale: float):
    """The collision driver's ``group`` function with the ``pads`` geoms turned by ``rotation`` first."""
    ids = jnp.asarray(pads)

    def turned(m, d, key, geom):
        pos, mat = d.geom_xpos[ids], d.geom_xmat[ids]
        hand = jnp.mean(pos, axis=0)
        r = rotation(hand, scale)
        d = d.replace(geom_xpos=d.geom_xpos.at[ids].set(hand + (pos - hand) @ r.T),
                      geom_xmat=d.geom_xmat.at[ids].set(jnp.einsum("ij,pjk->pik", r, mat)))  # fmt: skip
        return group(m, d, key, geom)

    turned.ncon = group.ncon
    return turned


def scale_of(m) -> float:
    """The model's ``hand_pitch`` numeric (an MjModel), 0 without one."""
    names = [m.numeric(i).name for i in range(m.nnumeric)]
    return float(np.asarray(m.numeric(NUMERIC).data)[0]) if NUMERIC in names else 0.0


def wrap(m, collide: dict) -> dict:
    """``collide`` ({(type1, type2): group}, as ``envs/mjx_patch.py`` takes it) with the pads' pairs pitched where
    model ``m`` asks for it: the puck's (``envs/box_cylinder.py``) and the table's (plane-box, MJX's own unless
    ``collide`` replaces it)."""
    scale = scale_of(m)
    if scale == 0:
        return collide
    from mujoco.mjx._src import collision_driver
    from mujoco.mjx._src.types import GeomType

    pads = tuple(m.geom(name).id for name in PADS)
    keys = ((GeomType.CYLINDER, GeomType.BOX), (GeomType.PLANE, GeomType.BOX))
    own = {key: collide.get(key, collision_driver._COLLISION_FUNC.get(key)) for key in keys}
    return {**collide, **{key: pitched(group, pads, scale) for key, group in own.items() if group is not None}}
