"""Fetch-style tasks (Reach, Push, Slide, PickAndPlace) as pure MJX functions.

Each follows Gymnasium-Robotics ``Fetch*-v4`` (models in ``envs/fetch/models.py``): the 25-float
observation in the reference's order (10 for Reach), achieved goal = object position (grip position
for Reach), sparse reward ``-(d > threshold)``, 50-step episodes, action ``a`` in [-1, 1]^4 moving
the gripper target by ``0.05 * a[:3]`` per 0.04 s control step.

Gripper target: as in the reference, the *current* grip position plus ``0.05 * a[:3]``, clipped to a workspace
box whose floor keeps the fingertips at or above the table (with ``finger_table`` 2.5 cm lower, where the fingers'
contact with the table holds them), then within the arm's reach (``control``; ``workspace="box"`` drops it): the
actuator control, which ``Physics`` holds (with ``drive="weld"``, ``simulate`` puts a mocap body there).

``State.physics`` (a ``Physics``) is the complete simulator state: qpos, qvel, ctrl, time and the
Newton solver's warm start. Restoring a saved ``State`` and replaying the same actions reproduces the
trajectory bit for bit, which SELECT's restore-and-replay relies on.

Defaults: 10 substeps of 4 ms (the reference's 20 of 2 ms; Slide's), Newton with 4 iterations and 4 line-search
iterations (Slide: 10): half the physics cost, the scripted controllers' success kept. ``physics``: ``kernels``
(parts of the step replaced by equivalents equal to float rounding, ``envs/fetch/kernels.py``) or ``mjx`` as it is.
"""

from __future__ import annotations

import dataclasses

import jax
import jax.numpy as jnp

from envs.base import GoalEnv, State, flag_invalid, make_data, mjx_substeps
from envs.fetch import control, kernels, models, observation
from envs.fetch.observation import Physics
from envs.physics import BACKENDS, KERNELS_CHECKED, in_use, kernels_checked
from envs.settings import check, check_integer

MIN_OBJECT_DISTANCE = 0.1  # the object starts at least this far from the gripper in xy
_OBJECT_TRIES = 64  # vectorised rejection sampling: P(all rejected) <= (pi / 4) ** 64 ~ 2e-7
GOAL_LIFT_MAX = 0.45
GRASP_ABOVE_SITE = 0.01  # a grasped cube's centre above the grip site: inside the fingers' 6 cm height


def experimental(default, **metadata):
    """A task field ``--help`` marks as experimental: the parity study's variants, training-only starts;
    ``metadata`` adds flags (``numerics_only``: see ``GoalEnv.settings``)."""
    return dataclasses.field(default=default, metadata={"experimental": True, **metadata})


@dataclasses.dataclass(frozen=True)
class _FetchTask(GoalEnv):
    """Shared machinery; subclasses set the scene and the goal distribution."""

    distance_threshold: float = 0.05
    target_range: float = 0.15
    obj_range: float = 0.15
    max_episode_steps: int = 50
    timestep: float = 0.004
    substeps: int = 10
    iterations: int = 4
    ls_iterations: int = 4
    # the physics: MJX with parts of its step replaced by faster equivalents, equal to float rounding, as the options
    # below choose (kernels; envs/fetch/kernels.py), or MJX as it is (mjx). Stock MJX on a MuJoCo release other
    # than the one the kernels were checked on (envs/physics.py).
    physics: str = dataclasses.field(default="kernels", metadata={"numerics_only": True})
    # Parity-study options (experimental): the reference's variants of parts of the physics.
    # the table's collision shape: its top face as a plane (ending at its edges: edged, Slide), or the reference's box
    table: str = experimental("plane")
    # the closed finger block's collision shape (Push: pads, box or capsule, see models.py; Slide: the reference's
    # two box pads (pads, its default) or round tips (box), see envs/fetch/slide_fingers.py)
    finger: str = experimental("box")
    # how MJX factors its small dense systems: envs/small_cholesky.py or "library"
    cholesky: str = experimental("unrolled")
    # MJX's Newton solver as its loops, its line search written out (search), or that on a GPU only (gpu-search;
    # envs/solver_loops.py), or the whole solve one program per env, a Pallas kernel on a GPU (fused; on a GPU
    # only, MJX's loops on a CPU: gpu-fused; envs/fused_solver.py): equal to float rounding
    solver_loops: str = experimental("gpu-search", numerics_only=True)
    # the most envs in one batch that the physics kernels take, MJX's batched code above (0: any batch): one env
    # per program fills a GPU worse than batched operations at thousands of envs (envs/kernel_batch.py)
    kernel_envs: int = experimental(0, numerics_only=True)
    # plane-box and box-box contacts as MJX computes them, or as one program per pair, a Pallas kernel on a GPU
    # (fused; on a GPU only: gpu-fused; envs/fused_collision.py): the same contacts up to MJX's float ties
    collision: str = experimental("mjx", numerics_only=True)
    # GPU warps per env in the physics kernels above (Triton's default is 4): an env's solve is a chain of small
    # reductions, which one warp runs without crossing warps (experiments/NOTES.md, "Physics kernels, HER's updates")
    kernel_warps: int = experimental(1, numerics_only=True)
    # where the gripper target may go: the box and the reference arm's reach, or the box
    workspace: str = experimental("arm")
    # how the gripper follows its target: the PD drive, or the reference's weld law (models.mjcf)
    drive: str = experimental("pd")
    # Training only (experimental): this share of resets starts with the object between the closed fingers
    # (PickAndPlace), HER 2017's protocol; evaluation_task() resets it to 0: success is measured from standard starts.
    grasped_starts: float = experimental(0.0)
    # How far above the fingertips-on-the-table height the gripper target may go down (m; the reference's 0.01)
    floor_clearance: float = experimental(0.0)
    # Friction of a contact between the fingers and the table (models.mjcf's finger_table; 0: none, Push's 1 the
    # reference's): the fingers as long as the reference's, so a gripper driven down at the table presses and drags.
    finger_table: float = experimental(0.0)
    # The gripper's mass in kg (0: the task's, models.mjcf): how hard the weld drive presses (Slide's pads sink
    # into the puck as deep as the reference's at 22 kg, its arm's effective mass along z at the grip site)
    gripper_mass: float = experimental(0.0, recorded_when_set=True)
    # Slide's pads pitched out as the reference arm stretches, by this fraction of its hand's tilt (hand_pitch.py)
    hand_pitch: float = experimental(0.0, recorded_when_set=True, unrecorded=0.0)
    # Held near its reach, the arm folds back toward its centre: control.DRIFT x this (1.5 the reference's drift)
    arm_drift: float = experimental(0.0, recorded_when_set=True, unrecorded=0.0)

    kind = ""  # models.KINDS entry
    has_object = True
    block_gripper = True
    target_in_the_air = False
    target_offset = (0.0, 0.0, 0.0)

    @property
    def moves_fingers(self) -> bool:
        return not self.block_gripper

    def __post_init__(self):
        n = self.kind
        check(self.distance_threshold > 0, f"{n}.distance_threshold", self.distance_threshold, "> 0")
        check(0 <= self.target_range <= 0.5, f"{n}.target_range", self.target_range, "in [0, 0.5]")
        if self.has_object:
            check(
                MIN_OBJECT_DISTANCE <= self.obj_range <= 0.5,
                f"{n}.obj_range",
                self.obj_range,
                f"in [{MIN_OBJECT_DISTANCE}, 0.5] (the object starts >= {MIN_OBJECT_DISTANCE} m from the gripper)",
            )
        tables = models.tables_for(n)
        check(self.table in tables, f"{n}.table", self.table, "one of " + ", ".join(tables))
        fingers = models.fingers_for(n)
        check(self.finger in fingers, f"{n}.finger", self.finger, "one of " + ", ".join(fingers))
        own = n == "slide" and self.finger == "pads"  # a contact MJX lacks, on the MuJoCo it was checked on
        ok = not own or kernels_checked()
        check(ok, f"{n}.finger", self.finger, f"box on this MuJoCo (pads' contact was checked on {KERNELS_CHECKED})")
        spaces = control.WORKSPACES
        check(self.workspace in spaces, f"{n}.workspace", self.workspace, "one of " + ", ".join(spaces))
        check(self.drive in models.DRIVES, f"{n}.drive", self.drive, "one of " + ", ".join(models.DRIVES))
        check(self.physics in BACKENDS, f"{n}.physics", self.physics, "one of " + ", ".join(BACKENDS))
        kernels.check_options(self)
        grasp_range = "in [0, 1]" if not self.block_gripper else "0 (the fingers are locked on this task)"
        ok = 0 <= self.grasped_starts <= 1 and (self.grasped_starts == 0 or not self.block_gripper)
        check(ok, f"{n}.grasped_starts", self.grasped_starts, grasp_range)
        check(0 <= self.floor_clearance <= 0.1, f"{n}.floor_clearance", self.floor_clearance, "in [0, 0.1] m")
        check(0 <= self.finger_table <= 2, f"{n}.finger_table", self.finger_table, "in [0, 2]")
        check(0 <= self.gripper_mass <= 100, f"{n}.gripper_mass", self.gripper_mass, "in [0, 100] kg (0: the task's)")
        ok = self.hand_pitch == 0 or (n == "slide" and self.finger == "pads" and 0 < self.hand_pitch <= 2)
        check(ok, f"{n}.hand_pitch", self.hand_pitch, "0 off Slide's pads (finger=box: add hand_pitch=0), else (0, 2]")
        ok = 0 <= self.arm_drift <= 5 and (self.arm_drift == 0 or self.workspace == "arm")
        check(ok, f"{n}.arm_drift", self.arm_drift, "in [0, 5] in the arm's workspace (workspace=box: add arm_drift=0)")
        check_integer(f"{n}.max_episode_steps", self.max_episode_steps, 1)
        check(0 < self.timestep <= 0.01, f"{n}.timestep", self.timestep, "in (0, 0.01] seconds")
        check_integer(f"{n}.substeps", self.substeps, 1, 100)
        check_integer(f"{n}.iterations", self.iterations, 1, 100)
        check_integer(f"{n}.ls_iterations", self.ls_iterations, 1, 100)

    # ---- sizes -------------------------------------------------------------------------------
    obs_size = property(lambda self: 25 if self.has_object else 10)
    goal_size = property(lambda self: 3)
    achieved_goal_start = property(lambda self: 3 if self.has_object else 0)  # object, else grip position
    success_distance = property(lambda self: self.distance_threshold)
    action_size = property(lambda self: 4)
    episode_length = property(lambda self: self.max_episode_steps)

    @property
    def dt(self) -> float:
        return self.timestep * self.substeps

    # ---- model -------------------------------------------------------------------------------
    def model_options(self) -> dict:
        """``models.mjcf``'s keywords this task sets."""
        return dict(
            timestep=float(self.timestep),
            iterations=int(self.iterations),
            ls_iterations=int(self.ls_iterations),
            table=str(self.table),
            finger=str(self.finger),
            drive=str(self.drive),
            finger_table=float(self.finger_table),
            **({"gripper_mass": float(self.gripper_mass)} if self.gripper_mass else {}),
            **({"hand_pitch": float(self.hand_pitch)} if self.hand_pitch else {}),
        )

    @property
    def built(self):
        return models.build(self.kind, **self.model_options())

    @property
    def mj_model(self):
        return self.built[0]

    @property
    def mjx_model(self):
        return self.built[1]

    @property
    def layout(self) -> models.Layout:
        return self.built[2]

    # ---- observation -------------------------------------------------------------------------
    def _observe(self, phys: Physics) -> tuple[jax.Array, jax.Array]:
        return observation.observe(self.layout, self.dt, self.has_object, phys)

    def _state(self, phys: Physics, goal: jax.Array, step: jax.Array, invalid: jax.Array) -> State:
        obs, achieved = self._observe(phys)
        ok = self.success(achieved, goal)
        return State(
            physics=phys,
            obs=obs,
            achieved_goal=achieved,
            desired_goal=goal,
            reward=self.reward_of(achieved, goal),
            success=ok,
            step=step,
            invalid=invalid,
        )

    # ---- reset -------------------------------------------------------------------------------
    def _object_xy(self, key: jax.Array) -> jax.Array:
        home = jnp.asarray(self.layout.grip_home[:2])
        offs = jax.random.uniform(key, (_OBJECT_TRIES, 2), minval=-self.obj_range, maxval=self.obj_range)
        dist = jnp.linalg.norm(offs, axis=-1)
        ok = dist >= MIN_OBJECT_DISTANCE
        idx = jnp.where(jnp.any(ok), jnp.argmax(ok), jnp.argmax(dist))
        return home + offs[idx]

    def _goal(self, key: jax.Array) -> jax.Array:
        k_xyz, k_air, k_lift = jax.random.split(key, 3)
        home = jnp.asarray(self.layout.grip_home)
        goal = home + jax.random.uniform(k_xyz, (3,), minval=-self.target_range, maxval=self.target_range)
        if not self.has_object:
            return goal
        goal = goal + jnp.asarray(self.target_offset)
        goal = goal.at[2].set(self.layout.object_rest_z)
        if self.target_in_the_air:
            lift = jax.random.uniform(k_lift, (), minval=0.0, maxval=GOAL_LIFT_MAX)
            goal = goal.at[2].add(jnp.where(jax.random.uniform(k_air) < 0.5, lift, 0.0))
        return goal

    def evaluation_task(self) -> _FetchTask:
        return dataclasses.replace(self, grasped_starts=0.0) if self.grasped_starts else self

    def reset(self, key: jax.Array) -> State:
        lay = self.layout
        k_obj, k_goal, k_grasp = jax.random.split(key, 3)
        qpos = jnp.zeros(lay.nq)
        if self.has_object:
            xyz = jnp.append(self._object_xy(k_obj), lay.object_rest_z)
            o = lay.object_q
            if self.grasped_starts:
                held = jax.random.uniform(k_grasp) < self.grasped_starts
                xyz = jnp.where(held, jnp.asarray(lay.grip_home) + jnp.array([0.0, 0.0, GRASP_ABOVE_SITE]), xyz)
                f = lay.finger_q  # each finger's inner face on a side of the cube; the zero control squeezes
                qpos = qpos.at[f : f + 2].set(jnp.where(held, models.OBJECT_HALF, 0.0))
            qpos = qpos.at[o : o + 7].set(jnp.concatenate([xyz, jnp.array([1.0, 0.0, 0.0, 0.0])]))
        phys = Physics(
            qpos=qpos,
            qvel=jnp.zeros(lay.nv),
            ctrl=jnp.zeros(lay.nu),
            time=jnp.zeros(()),
            qacc_warmstart=jnp.zeros(lay.nv),
        )
        return self._state(phys, self._goal(k_goal), jnp.int32(0), jnp.bool_(False))

    # ---- step --------------------------------------------------------------------------------
    def _control(self, phys: Physics, action: jax.Array) -> jax.Array:
        lay, g = self.layout, self.layout.grip_q
        reach = lay.reach_center if self.workspace == "arm" else None
        lo, hi = (*lay.workspace_lo[:2], lay.workspace_lo[2] + self.floor_clearance), lay.workspace_hi
        q = phys.qpos[g : g + 3]
        target = control.gripper_target(q, action[:3], lay.grip_home, lo, hi, reach, xp=jnp, drift=self.arm_drift)
        ctrl = phys.ctrl.at[0:3].set(target)
        if lay.finger_q is not None:
            f = lay.finger_q
            fingers = jnp.clip(phys.qpos[f : f + 2] + action[3], 0.0, 0.2)
            ctrl = ctrl.at[3:5].set(fingers)
        return ctrl

    def simulate(self, phys: Physics, ctrl: jax.Array) -> Physics:
        """``substeps`` MJX steps from ``phys`` with control ``ctrl``."""
        model = self.mjx_model

        def step():
            data = make_data(model)
            if self.drive == "weld":  # the constraint pulls the gripper to the mocap body, put at the target
                home = jnp.asarray(self.layout.grip_home, data.mocap_pos.dtype)
                data = data.replace(mocap_pos=data.mocap_pos.at[0].set(home + ctrl[0:3]))
            return mjx_substeps(model, data, phys.replace(ctrl=ctrl), self.substeps)

        if self.physics_in_use() != "kernels":
            with models.own_contacts(self.mj_model):
                return step()
        with kernels.mjx_with_kernels(self):
            return step()

    def physics_in_use(self) -> str:
        """The backend this task's steps run: its ``physics``, stock MJX on a MuJoCo the kernels were not
        checked on (``envs/physics.py``)."""
        return in_use(self.physics)

    def kernel_fallback(self, error: BaseException) -> str | None:
        return kernels.kernel_fallback(self, error)

    def _action(self, action: jax.Array) -> jax.Array:
        """The action (any leading batch axes) as the control law reads it: clipped to [-1, 1], the fingers'
        command zeroed where they are locked."""
        action = jnp.clip(action, -1.0, 1.0)
        if self.block_gripper:
            action = action.at[..., 3].set(0.0)
        return action

    def step(self, state: State, action: jax.Array) -> State:
        phys = state.physics
        phys = self.simulate(phys, self._control(phys, self._action(action)))
        out = self._state(phys, state.desired_goal, state.step + 1, state.invalid)
        return flag_invalid(out)

    def with_goal(self, state: State, goal: jax.Array) -> State:
        return self._state(state.physics, goal, state.step, state.invalid)

    def success(self, achieved: jax.Array, desired: jax.Array) -> jax.Array:
        return jnp.linalg.norm(achieved - desired, axis=-1) < self.distance_threshold


@dataclasses.dataclass(frozen=True)
class Reach(_FetchTask):
    """Move the grip site to a goal within 0.15 m of its start (no object)."""

    kind = "reach"
    has_object = False
    target_in_the_air = True


@dataclasses.dataclass(frozen=True)
class Push(_FetchTask):
    """Push a 5 cm cube to a goal on the table; fingers locked closed. The fingers touch the table
    (``finger_table``, the reference's friction 1): a policy trained where pressing down on the table
    costs nothing presses there, and in the reference that drags its gripper and loses the cube. The finger
    block has the reference pads' extent (``finger="pads"``): a smaller one pushes the cube less far per
    command than the reference's, and a policy trained on it overshoots there."""

    finger_table: float = 1.0
    finger: str = "pads"
    # the solve and the box contacts as kernels on a GPU, where each made Push's step faster (BENCHMARKS.md)
    solver_loops: str = experimental("gpu-fused", numerics_only=True)
    collision: str = experimental("gpu-fused", numerics_only=True)
    kind = "push"


@dataclasses.dataclass(frozen=True)
class Slide(_FetchTask):
    """Strike a low-friction puck (a cylinder on a plane top ending at the reference table's edges) to a goal
    0.4 m ahead, out of reach, at the reference's 2 ms step (at 4 ms hard strikes went erratically far). The
    fingers are the reference's box pads (a box-cylinder contact MJX lacks, envs/fetch/slide_fingers.py) that
    touch the table, pitch out as its hand does at stretch (``hand_pitch``), moved by its weld law with its arm's
    effective mass, the arm folding back when held at stretch (``arm_drift``): with round fingertips, or no table
    edge, policies rode the puck and failed in the reference (experiments/NOTES.md, "Slide's table edge")."""

    timestep: float = 0.002
    substeps: int = 20
    table: str = "edged"
    finger: str = "pads"
    finger_table: float = 1.0
    drive: str = "weld"
    gripper_mass: float = dataclasses.field(default=22.0, metadata={"recorded_when_set": True, "unrecorded": 0.0})
    hand_pitch: float = dataclasses.field(default=1.0, metadata={"recorded_when_set": True, "unrecorded": 0.0})
    arm_drift: float = dataclasses.field(default=1.5, metadata={"recorded_when_set": True, "unrecorded": 0.0})
    obj_range: float = 0.1
    target_range: float = 0.3
    iterations: int = 10  # 4 let a resting low-friction puck creep in float32 (up to 10 cm in 50 steps)
    # the solve as a kernel on a GPU for a step's envs, MJX's batched solve for SELECT's thousands of replayed
    # rows, where the kernel fills the GPU worse: the command compiled faster so (BENCHMARKS.md)
    solver_loops: str = experimental("gpu-fused", numerics_only=True)
    kernel_envs: int = experimental(2048, numerics_only=True)
    kind = "slide"
    target_offset = (0.4, 0.0, 0.0)


@dataclasses.dataclass(frozen=True)
class PickAndPlace(_FetchTask):
    """Carry a cube to a goal on the table or, half the time, up to 0.45 m above it."""

    # the finger joints' response to their actuators (models.FINGER_DRIVES): the reference's, or the fast one
    finger_drive: str = experimental("reference")
    # the solve and the box contacts as kernels on a GPU for a step's envs, MJX's batched code for SELECT's
    # thousands of replayed rows, where the kernels fill the GPU worse: the command ran faster so (BENCHMARKS.md)
    solver_loops: str = experimental("gpu-fused", numerics_only=True)
    collision: str = experimental("gpu-fused", numerics_only=True)
    kernel_envs: int = experimental(2048, numerics_only=True)
    kind = "pick_and_place"
    block_gripper = False
    target_in_the_air = True

    def __post_init__(self):
        super().__post_init__()
        drives = models.FINGER_DRIVES
        ok = self.finger_drive in drives
        check(ok, f"{self.kind}.finger_drive", self.finger_drive, "one of " + ", ".join(drives))

    def model_options(self) -> dict:
        return {**super().model_options(), "finger_drive": str(self.finger_drive)}


TASKS = {"reach": Reach, "push": Push, "slide": Slide, "pick_and_place": PickAndPlace}
