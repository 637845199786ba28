"""SawyerDoor (the paper's appendix E): multiworld's SawyerDoorHookEnv in MJX, goal-conditioned.

A hand opens a hinged door to a goal angle. The door is a panel on a vertical hinge (range [0, 1]
rad, damped so that a released door stops) with a hook on its face: a bar held off the panel by a
stub at its foot, open from above. The hand, lowered into the hook, pulls the door open against the
bar and pushes it back against the panel, so it can set the door to any angle of the goal range
from either side. The state is the hand's XYZ and the door angle; the goal is the angle, uniform in
[0, 0.83] rad as in GCSL's use of multiworld, m(s) = s[-1:]; success is |angle - goal| <= 0.06 rad,
50 steps an episode.

Simplified from multiworld:
- No Sawyer arm, and the hook is on the door rather than on the hand: the hand is a sphere on three
  world-aligned slide joints, each driven by a position actuator (kp = m w^2, critical joint damping)
  toward its current position plus ``action_scale * a``, as Fetch's gripper here
  (``envs/fetch/models.py``). Multiworld pulls the hand to a mocap body by a weld; a welded free
  body would add three rotational dofs and six constraint rows to every MJX step, for a hand whose
  orientation never matters here.
- ``action_scale`` is 3 cm, so that 50 steps cover the way into the hook and round the door's arc
  with room to spare; the hand's target stays in a box about the hook's path (``WORKSPACE``), as
  GCSL's 15 x 20 x 15 cm hand box keeps multiworld's hook near the handle.
- No gravity: the hinge is vertical and the hand position-driven, so it would only need compensating.
- The hand touches only the door's three parts, without friction; nothing else collides.
- The hand starts within 2 cm of a point above the hook, the door closed, as multiworld resets both
  to fixed places."""

from __future__ import annotations

import dataclasses
import functools

import jax
import jax.numpy as jnp
from flax import struct

from envs.base import GoalEnv, State, flag_invalid, make_data, mjx_substeps, put_model
from envs.settings import check, check_integer

GOAL_MAX = 0.83  # the largest goal angle (GCSL's multiworld settings), rad
HINGE_MAX = 1.0  # the hinge's upper limit, rad
# The door in its own frame: hinge on the z axis, panel along +x, opening toward +y (the hook's side).
PANEL = (0.3, 0.01, 0.3)  # length, half thickness, height (m)
HOOK_X = 0.25  # the hook's distance from the hinge
HOOK_Y = 0.07  # the bar's axis off the panel's centre plane
HOOK_Z = (0.1, 0.2)  # the bar's foot (where the stub joins it) and top
BAR_RADIUS = 0.01
HAND_RADIUS = 0.02
HAND_MASS = 1.0
DRIVE_OMEGA = 50.0  # rad/s
# The hand in the hook: halfway between the panel's face and the bar, halfway up the bar.
POCKET = (HOOK_X, (PANEL[1] + HOOK_Y - BAR_RADIUS) / 2, (HOOK_Z[0] + HOOK_Z[1]) / 2)
HAND_HOME = (HOOK_X, 0.15, 0.25)  # above the hook, in front of the closed door
HAND_START_NOISE = 0.02  # the start is uniform within this of HAND_HOME on each axis
# The hand's target stays in this box, which holds the hook's pocket over the hinge's whole range.
WORKSPACE = ((0.1, 0.0, 0.12), (0.3, 0.25, 0.27))

_XML = """
<mujoco model="sawyer_door">
  <compiler angle="radian" autolimits="true"/>
  <option timestep="{timestep}" gravity="0 0 0" integrator="Euler" iterations="{iterations}"
          ls_iterations="{iterations}"/>
  <default><geom contype="0" conaffinity="0"/></default>
  <worldbody>
    <body name="door">
      <joint name="hinge" type="hinge" axis="0 0 1" range="0 {hinge_max}" damping="{door_damping}"/>
      <geom name="panel" type="box" pos="{px} 0 {pz}" size="{px} {pt} {pz}" mass="2"/>
      <geom name="stub" type="box" pos="{hx} {sy} {sz}" size="{bar} {sh} {bar}" mass="0.05"/>
      <geom name="bar" type="capsule" fromto="{hx} {hy} {sz} {hx} {hy} {bz}" size="{bar}" mass="0.05"/>
    </body>
    <body name="hand">
      <joint name="hand_x" type="slide" axis="1 0 0" damping="{hand_damping}"/>
      <joint name="hand_y" type="slide" axis="0 1 0" damping="{hand_damping}"/>
      <joint name="hand_z" type="slide" axis="0 0 1" damping="{hand_damping}"/>
      <geom name="hand" type="sphere" size="{hand}" mass="{hand_mass}"/>
    </body>
  </worldbody>
  <contact>
    <pair geom1="hand" geom2="panel" condim="1"/>
    <pair geom1="hand" geom2="stub" condim="1"/>
    <pair geom1="hand" geom2="bar" condim="1"/>
  </contact>
  <actuator>
    <position joint="hand_x" kp="{kp}"/>
    <position joint="hand_y" kp="{kp}"/>
    <position joint="hand_z" kp="{kp}"/>
  </actuator>
</mujoco>
"""


@struct.dataclass
class Physics:
    """Everything the future depends on: hand and door joint states and the solver's warm start (the
    actuators' targets are set from the hand's position each step)."""

    qpos: jax.Array  # [4]: hinge angle, hand XYZ
    qvel: jax.Array  # [4]
    qacc_warmstart: jax.Array  # [4]


def pocket(angle: jax.Array) -> jax.Array:
    """The world XYZ of the hook's pocket with the door at ``angle``."""
    c, s = jnp.cos(angle), jnp.sin(angle)
    x, y, z = POCKET
    return jnp.stack([c * x - s * y, s * x + c * y, jnp.full_like(angle, z)], axis=-1)


@dataclasses.dataclass(frozen=True)
class SawyerDoor(GoalEnv):
    """Open a door to a goal angle with a hand in its hook; 50 control steps of 0.04 s."""

    max_episode_steps: int = 50
    success_threshold: float = 0.06  # on |angle - goal|, rad (the paper's)
    action_scale: float = 0.03  # metres of hand target per unit action per control step
    door_damping: float = 1.0  # N m s / rad on the hinge
    timestep: float = 0.01
    frame_skip: int = 4
    iterations: int = 4  # Newton iterations (and line-search iterations) per physics step

    def __post_init__(self):
        check_integer("sawyer_door.max_episode_steps", self.max_episode_steps, 2)
        check(
            0 < self.success_threshold < GOAL_MAX,
            "sawyer_door.success_threshold",
            self.success_threshold,
            f"in (0, {GOAL_MAX}) rad",
        )
        check(0 < self.action_scale <= 0.1, "sawyer_door.action_scale", self.action_scale, "in (0, 0.1] m")
        check(self.door_damping > 0, "sawyer_door.door_damping", self.door_damping, "> 0 (N m s/rad)")
        check(0 < self.timestep <= 0.01, "sawyer_door.timestep", self.timestep, "in (0, 0.01] seconds")
        check_integer("sawyer_door.frame_skip", self.frame_skip, 1, 40)
        check_integer("sawyer_door.iterations", self.iterations, 1, 100)

    obs_size = property(lambda self: 4)
    goal_size = property(lambda self: 1)
    achieved_goal_start = property(lambda self: 3)  # the door angle
    success_distance = property(lambda self: self.success_threshold)
    action_size = property(lambda self: 3)
    episode_length = property(lambda self: self.max_episode_steps)
    dt = property(lambda self: self.timestep * self.frame_skip)

    def mjcf(self) -> str:
        length, half_thick, height = PANEL
        return _XML.format(
            timestep=self.timestep,
            iterations=self.iterations,
            hinge_max=HINGE_MAX,
            door_damping=self.door_damping,
            px=length / 2,
            pt=half_thick,
            pz=height / 2,
            hx=HOOK_X,
            hy=HOOK_Y,
            sy=(half_thick + HOOK_Y) / 2,
            sh=(HOOK_Y - half_thick) / 2,
            sz=HOOK_Z[0],
            bz=HOOK_Z[1],
            bar=BAR_RADIUS,
            hand=HAND_RADIUS,
            hand_mass=HAND_MASS,
            hand_damping=2 * HAND_MASS * DRIVE_OMEGA,
            kp=HAND_MASS * DRIVE_OMEGA**2,
        )

    @functools.cached_property
    def built(self):
        import mujoco

        model = mujoco.MjModel.from_xml_string(self.mjcf())
        return model, put_model(model, impl="jax")  # one implementation on every backend

    @property
    def mj_model(self):
        return self.built[0]

    @property
    def mjx_model(self):
        return self.built[1]

    def _state(self, phys: Physics, goal: jax.Array, step: jax.Array, invalid: jax.Array) -> State:
        angle = phys.qpos[:1]
        obs = jnp.concatenate([phys.qpos[1:4], angle])
        ok = self.success(angle, goal)
        return State(
            physics=phys,
            obs=obs,
            achieved_goal=angle,
            desired_goal=goal,
            reward=ok.astype(jnp.float32) - 1.0,
            success=ok,
            step=step,
            invalid=invalid,
        )

    def reset(self, key: jax.Array) -> State:
        k_hand, k_goal = jax.random.split(key)
        hand = jnp.asarray(HAND_HOME) + jax.random.uniform(
            k_hand, (3,), minval=-HAND_START_NOISE, maxval=HAND_START_NOISE
        )
        goal = jax.random.uniform(k_goal, (1,), maxval=GOAL_MAX)
        qpos = jnp.concatenate([jnp.zeros(1), hand])
        phys = Physics(qpos=qpos, qvel=jnp.zeros(4), qacc_warmstart=jnp.zeros(4))
        return self._state(phys, goal, jnp.int32(0), jnp.bool_(False))

    def step(self, state: State, action: jax.Array) -> State:
        model = self.mjx_model
        phys = state.physics
        lo, hi = (jnp.asarray(b) for b in WORKSPACE)
        target = jnp.clip(phys.qpos[1:4] + self.action_scale * jnp.clip(action, -1.0, 1.0), lo, hi)
        phys = mjx_substeps(model, make_data(model).replace(ctrl=target), phys, self.frame_skip)
        return flag_invalid(self._state(phys, state.desired_goal, state.step + 1, state.invalid))

    def with_goal(self, state: State, goal: jax.Array) -> State:
        return self._state(state.physics, goal, state.step, state.invalid)

    def success(self, achieved: jax.Array, desired: jax.Array) -> jax.Array:
        return jnp.abs(achieved - desired)[..., 0] <= self.success_threshold


def scripted(state: State, scale: float = SawyerDoor.action_scale, turn: float = 0.15) -> jax.Array:
    """Over the hook, down into it, then round the hinge: the hook's pocket at the door's angle moved at
    most ``turn`` rad toward the goal, so the hand leads the door by the bar or the panel and stays in
    the hook either way. ``scale`` is the task's ``action_scale``."""
    hand, angle, goal = state.obs[:3], state.obs[3], state.desired_goal[0]
    here = pocket(angle)
    lateral = jnp.linalg.norm((hand - here)[:2])
    in_hook = (lateral < 0.015) & (hand[2] < HOOK_Z[1])  # within the pocket's slack and the hook's contacts
    above = here.at[2].set(HAND_HOME[2])
    lead = pocket(angle + jnp.clip(goal - angle, -turn, turn))
    target = jnp.where(in_hook, lead, jnp.where(lateral < 0.01, here, above))  # descend only when over it
    return jnp.clip((target - hand) / scale, -1.0, 1.0)
