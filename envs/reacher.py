"""Reacher (the paper's appendix E): Gym's two-joint planar arm in MJX, goal-conditioned.

The model follows Gym's ``reacher.xml`` (links of 0.1 and 0.11 m, joint damping 1, armature 1, motor
gear 200, 0.01 s steps, 2 per control step) without the target body and without contacts, which
Gym's arm never makes. The state is the seed's 11 numbers: cos and sin of both joint angles, the
angles, their velocities, and the fingertip's XYZ; the goal is the fingertip's XY, m(s) = s[-3:-1].
Success is the seed's squared distance <= 0.05 (``success_threshold``): about 22 cm, lenient on an
arm of 21 cm, so a stricter threshold is one option away."""

from __future__ import annotations

import dataclasses
import functools

import jax
import jax.numpy as jnp
from flax import struct

from envs.base import GoalEnv, State, flag_invalid, make_data, mjx_substeps, put_model
from envs.settings import check, check_integer

LINKS = (0.1, 0.11)  # shoulder to elbow, elbow to fingertip (Gym's fingertip body sits at 0.11)
FINGERTIP_Z = 0.01
GOAL_RADIUS = 0.2  # Gym's targets: uniform in the disc of this radius

_XML = """
<mujoco model="reacher">
  <compiler angle="radian"/>
  <option timestep="{timestep}" integrator="RK4">
    <flag contact="disable"/>
  </option>
  <default><joint armature="1" damping="1" limited="true"/></default>
  <worldbody>
    <body name="body0" pos="0 0 .01">
      <joint axis="0 0 1" limited="false" name="joint0" type="hinge"/>
      <geom fromto="0 0 0 0.1 0 0" name="link0" size=".01" type="capsule" mass="0.0356"/>
      <body name="body1" pos="0.1 0 0">
        <joint axis="0 0 1" name="joint1" range="-3.0 3.0" type="hinge"/>
        <geom fromto="0 0 0 0.1 0 0" name="link1" size=".01" type="capsule" mass="0.0356"/>
        <body name="fingertip" pos="0.11 0 0">
          <geom name="fingertip" pos="0 0 0" size=".01" type="sphere" mass="0.00419"/>
        </body>
      </body>
    </body>
  </worldbody>
  <actuator>
    <motor ctrllimited="true" ctrlrange="-1.0 1.0" gear="200.0" joint="joint0"/>
    <motor ctrllimited="true" ctrlrange="-1.0 1.0" gear="200.0" joint="joint1"/>
  </actuator>
</mujoco>
"""


@struct.dataclass
class Physics:
    """Everything the future depends on: the arm's joint state and the solver's warm start."""

    qpos: jax.Array  # [2]
    qvel: jax.Array  # [2]
    qacc_warmstart: jax.Array  # [2]


def fingertip(q: jax.Array) -> jax.Array:
    """The fingertip's XYZ from the joint angles (exact forward kinematics of the two links)."""
    a, b = q[..., 0], q[..., 0] + q[..., 1]
    x = LINKS[0] * jnp.cos(a) + LINKS[1] * jnp.cos(b)
    y = LINKS[0] * jnp.sin(a) + LINKS[1] * jnp.sin(b)
    return jnp.stack([x, y, jnp.full_like(x, FINGERTIP_Z)], axis=-1)


@dataclasses.dataclass(frozen=True)
class Reacher(GoalEnv):
    """Bring the fingertip to a goal in the plane; 50 control steps of 0.02 s."""

    max_episode_steps: int = 50
    success_threshold: float = 0.05  # on the squared distance, m^2 (the seed's epsilon)
    timestep: float = 0.01
    frame_skip: int = 2

    def __post_init__(self):
        check_integer("reacher.max_episode_steps", self.max_episode_steps, 2)
        check(self.success_threshold > 0, "reacher.success_threshold", self.success_threshold, "> 0 (m^2)")
        check(0 < self.timestep <= 0.02, "reacher.timestep", self.timestep, "in (0, 0.02] seconds")
        check_integer("reacher.frame_skip", self.frame_skip, 1, 20)

    obs_size = property(lambda self: 11)
    goal_size = property(lambda self: 2)
    achieved_goal_start = property(lambda self: 8)  # the fingertip's XY
    success_distance = property(lambda self: self.success_threshold**0.5)
    action_size = property(lambda self: 2)
    episode_length = property(lambda self: self.max_episode_steps)
    dt = property(lambda self: self.timestep * self.frame_skip)

    @functools.cached_property
    def built(self):
        import mujoco

        model = mujoco.MjModel.from_xml_string(_XML.format(timestep=self.timestep))
        return model, put_model(model)

    @property
    def mj_model(self):
        return self.built[0]

    @property
    def mjx_model(self):
        return self.built[1]

    def _state(self, phys: Physics, goal: jax.Array, step: jax.Array, invalid: jax.Array) -> State:
        q, v = phys.qpos, phys.qvel
        tip = fingertip(q)
        obs = jnp.concatenate([jnp.cos(q), jnp.sin(q), q, v, tip])
        ok = self.success(tip[:2], goal)
        return State(
            physics=phys,
            obs=obs,
            achieved_goal=tip[:2],
            desired_goal=goal,
            reward=ok.astype(jnp.float32) - 1.0,
            success=ok,
            step=step,
            invalid=invalid,
        )

    def reset(self, key: jax.Array) -> State:
        k_q, k_v, k_r, k_a = jax.random.split(key, 4)
        qpos = jax.random.uniform(k_q, (2,), minval=-0.1, maxval=0.1)
        qvel = jax.random.uniform(k_v, (2,), minval=-0.005, maxval=0.005)
        radius = GOAL_RADIUS * jnp.sqrt(jax.random.uniform(k_r))  # uniform over the disc
        angle = jax.random.uniform(k_a, minval=-jnp.pi, maxval=jnp.pi)
        goal = radius * jnp.stack([jnp.cos(angle), jnp.sin(angle)])
        phys = Physics(qpos=qpos, qvel=qvel, qacc_warmstart=jnp.zeros(2))
        return self._state(phys, goal, jnp.int32(0), jnp.bool_(False))

    def step(self, state: State, action: jax.Array) -> State:
        model = self.mjx_model
        data = make_data(model).replace(ctrl=jnp.clip(action, -1.0, 1.0))
        phys = mjx_substeps(model, data, state.physics, self.frame_skip)
        return flag_invalid(self._state(phys, state.desired_goal, state.step + 1, state.invalid))

    def with_goal(self, state: State, goal: jax.Array) -> State:
        return self._state(state.physics, goal, state.step, state.invalid)

    def success(self, achieved: jax.Array, desired: jax.Array) -> jax.Array:
        return jnp.sum((achieved - desired) ** 2, axis=-1) <= self.success_threshold


def scripted(state: State, kp: float = 0.5, kd: float = 0.05) -> jax.Array:
    """Inverse kinematics to the goal (elbow sign kept from the current pose), then a PD torque."""
    q, v = state.obs[4:6], state.obs[6:8]
    g = state.desired_goal
    l1, l2 = LINKS
    r2 = jnp.clip(jnp.sum(g**2), (l2 - l1) ** 2 + 1e-6, (l1 + l2) ** 2 - 1e-6)
    elbow = jnp.arccos(jnp.clip((r2 - l1**2 - l2**2) / (2 * l1 * l2), -1.0, 1.0))
    elbow = jnp.where(q[1] < 0, -elbow, elbow)
    shoulder = jnp.arctan2(g[1], g[0]) - jnp.arctan2(l2 * jnp.sin(elbow), l1 + l2 * jnp.cos(elbow))
    err = jnp.stack([shoulder, elbow]) - q
    err = err.at[0].set(jnp.arctan2(jnp.sin(err[0]), jnp.cos(err[0])))  # the shoulder turns freely
    return jnp.clip(kp * err - kd * v, -1.0, 1.0)
