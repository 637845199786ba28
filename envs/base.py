"""The contract every goal-conditioned task speaks, so SPLID can save, restore and replay it.

A task is a frozen dataclass (hashable, so jitted code may close over it) whose methods are pure:
``reset(key) -> State``, ``step(state, action) -> State``, ``with_goal(state, goal) -> State``.
``State.physics`` holds everything the future of the episode depends on, so a ``State`` saved
during exploration *is* the snapshot SELECT restores.
"""

from __future__ import annotations

import abc
import dataclasses
import functools
from typing import Any

import jax
import jax.numpy as jnp
from flax import struct


@struct.dataclass
class State:
    """One step of one episode; batch it with ``jax.vmap``."""

    physics: Any  # task-specific pytree: the complete simulator state
    obs: jax.Array  # [obs_size]
    achieved_goal: jax.Array  # [goal_size]
    desired_goal: jax.Array  # [goal_size]
    reward: jax.Array  # [] float32, sparse
    success: jax.Array  # [] bool, achieved within the threshold of desired
    step: jax.Array  # [] int32, control steps taken in this episode
    invalid: jax.Array  # [] bool, a NaN was seen: the episode is flagged, never silently used


def recorded_default(field: dataclasses.Field):
    """The value of ``field`` in a run that recorded none: its ``unrecorded`` metadata, else its default."""
    return field.metadata.get("unrecorded", field.default)


def _left_out_at(field: dataclasses.Field):
    """The value at which ``GoalEnv.settings`` leaves ``field`` out; a sentinel no value equals where it never is."""
    if field.metadata.get("recorded_when_set"):
        return recorded_default(field)
    return field.default if field.metadata.get("numerics_only") else _ALWAYS


_ALWAYS = object()


@dataclasses.dataclass(frozen=True)
class GoalEnv(abc.ABC):
    """Base for tasks. Subclasses are frozen dataclasses whose fields are the task's options."""

    moves_fingers = False  # whether the last action opens and closes fingers (a learner may explore it apart)

    def kernel_fallback(self, error: BaseException) -> str | None:
        """The task options that avoid a GPU kernel whose compile failed with ``error``; None where the task has
        no such kernel or the error is another."""
        return None

    def physics_in_use(self) -> str | None:
        """The code that steps this task's simulator (``envs/physics.py``), as a run records it in config.json;
        None where the task offers no choice."""
        return None

    def settings(self) -> dict:
        """Every option of this task, defaults included, by name: what a checkpoint records so that a
        resume under changed task defaults is caught, not silently continued. An option that changes
        only how the same arithmetic is computed (field metadata ``numerics_only``), or one added after
        runs were recorded (``recorded_when_set``), is left out at its default, or at the value those runs
        had (``unrecorded``), so runs recorded before it existed still match."""
        fields = [f for f in dataclasses.fields(self) if getattr(self, f.name) != _left_out_at(f)]
        return {"task": type(self).__name__, **{f.name: getattr(self, f.name) for f in fields}}

    @property
    @abc.abstractmethod
    def obs_size(self) -> int: ...

    @property
    @abc.abstractmethod
    def goal_size(self) -> int: ...

    @property
    @abc.abstractmethod
    def action_size(self) -> int: ...

    @property
    @abc.abstractmethod
    def achieved_goal_start(self) -> int:
        """Where the achieved goal begins in the observation: ``obs[start : start + goal_size]`` is
        ``achieved_goal``, so a policy can be fed the goal relative to it."""

    @property
    @abc.abstractmethod
    def success_distance(self) -> float:
        """The distance between achieved and desired goal within which ``success`` holds: the unit a
        policy sees the relative goal in, so that 1 is the edge of success on every task."""

    @property
    @abc.abstractmethod
    def episode_length(self) -> int: ...

    @abc.abstractmethod
    def reset(self, key: jax.Array) -> State: ...

    @abc.abstractmethod
    def step(self, state: State, action: jax.Array) -> State:
        """Advance one control step; actions are clipped to [-1, 1]."""

    @abc.abstractmethod
    def with_goal(self, state: State, goal: jax.Array) -> State:
        """The same simulator state pursuing ``goal``: what SELECT restores."""

    @abc.abstractmethod
    def success(self, achieved: jax.Array, desired: jax.Array) -> jax.Array:
        """Whether ``achieved`` is within the task's threshold of ``desired`` (broadcasts)."""

    def evaluation_task(self) -> GoalEnv:
        """The task a policy is judged on: this one with every training-only option (a start
        distribution that helps exploration) back at its standard setting."""
        return self

    def reward_of(self, achieved: jax.Array, desired: jax.Array) -> jax.Array:
        """Sparse reward; the Fetch convention -(not success). Tasks may override."""
        return self.success(achieved, desired).astype(jnp.float32) - 1.0


def flag_invalid(state: State) -> State:
    """Set ``invalid`` when any float in the state is NaN; stays set for the episode."""
    leaves = [x for x in jax.tree_util.tree_leaves(state) if jnp.issubdtype(x.dtype, jnp.floating)]
    bad = jnp.any(jnp.stack([jnp.any(jnp.isnan(x)) for x in leaves]))
    return state.replace(invalid=state.invalid | bad)


# XLA:CPU can hang when a vmapped MJX step of about 1,000 envs or more runs inside a loop
# (experiments/NOTES.md, "CPU step slices"). On the CPU the batch is therefore stepped in slices of
# this many envs; each env's step is independent, so only the schedule changes.
CPU_STEP_SLICE = 512


def _placed_on_cpu() -> bool:
    """Whether the computation being traced goes to a CPU: the ``jax.default_device`` in force (a CPU
    peer on a GPU host sets it), else the default backend."""
    dev = jax.config.jax_default_device
    if dev is None:
        return jax.default_backend() == "cpu"
    return (dev if isinstance(dev, str) else dev.platform) == "cpu"


def step_batch(env: GoalEnv, state: State, action: jax.Array) -> State:
    """``env.step`` over a leading batch axis: one vmap, or on the CPU ``lax.map`` over equal slices of at
    most ``CPU_STEP_SLICE`` envs. Equal slices (the batch padded with copies of its last env, whose
    steps are dropped) keep one batched copy of the step in the program, where a remainder slice would
    be a second copy to trace and compile."""
    step = _traced_once(env)
    n = action.shape[0]
    if n <= CPU_STEP_SLICE or not _placed_on_cpu():
        return jax.vmap(step)(state, action)
    slices = -(-n // CPU_STEP_SLICE)
    size = -(-n // slices)
    pad = slices * size - n
    if pad:
        state, action = jax.tree.map(lambda x: jnp.concatenate([x, jnp.repeat(x[-1:], pad, axis=0)]), (state, action))
    out = jax.lax.map(lambda sa: step(*sa), (state, action), batch_size=size)
    return jax.tree.map(lambda x: x[:n], out) if pad else out


def own_device() -> jax.Device:
    """The device a task's model and data are placed on: this process's first. MJX's default,
    ``jax.devices()[0]``, is process 0's under ``jax.distributed``, and an array there spans a device the
    other processes cannot address, which no program of theirs may close over or read."""
    return jax.local_devices()[0]


def put_model(mj_model, impl: str | None = None):
    """``mjx.put_model`` on ``own_device``; a task's model is built once and closed over by every program,
    so the first use may come from inside a jit trace."""
    from mujoco import mjx

    with jax.ensure_compile_time_eval():
        return mjx.put_model(mj_model, impl=impl, device=own_device())


def make_data(model):
    """``mjx.make_data`` of an MJX ``model`` on ``own_device``, in the model's implementation."""
    from mujoco import mjx

    return mjx.make_data(model, device=own_device(), impl=model.impl)


def data_with(data, phys):
    """MJX ``data`` with the fields of a task's ``phys`` (a flax struct named as MJX's ``Data`` fields) set."""
    return data.replace(**{f.name: getattr(phys, f.name) for f in dataclasses.fields(phys)})


def mjx_substeps(model, data, phys, substeps: int):
    """``substeps`` MJX steps of ``model`` from ``data`` with the fields of the task's ``phys`` (a flax
    struct named as MJX's ``Data`` fields) set; returns ``phys`` with those fields as they end.

    The loop carries ``phys`` alone, not the whole ``Data``: every field it carries is then batched from
    the start under ``vmap``, so JAX batches the step's body once, instead of a second time after finding
    that ``make_data``'s fields come out batched (a quarter of the Push chunk's tracing). A step reads
    nothing else of the previous one's ``Data``."""
    from mujoco import mjx

    names = [f.name for f in dataclasses.fields(phys)]

    def substep(_, p):
        d = mjx.step(model, data_with(data, p))
        return p.replace(**{n: getattr(d, n) for n in names})

    return jax.lax.fori_loop(0, substeps, substep, phys)


@functools.lru_cache(maxsize=64)
def _traced_once(env: GoalEnv):
    """``env.step`` as one jitted function per task: exploration, SELECT and evaluation step the same
    task at different batch sizes, and JAX traces the unbatched step once for all of them instead of
    once per caller (XLA inlines the call)."""
    return jax.jit(env.step)
