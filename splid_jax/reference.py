"""Evaluate a run's policy in the reference simulator, Gymnasium-Robotics ``Fetch*-v4`` (MuJoCo C, the
7-joint arm on its mocap weld), beside the same numbers in our MJX task; and trace both simulators
from the same starts.

``python -m splid_jax.evaluate RUN_DIR --reference`` needs the optional extra
(``pip install -e ".[reference]"``: gymnasium-robotics 1.4.2, which installs beside our mujoco).

Run-time fix. gymnasium-robotics 1.4.2's joint getters and setters (``utils/mujoco_utils.py``)
assert ``joint_type in (mjJNT_HINGE, mjJNT_SLIDE)``, which is False for the numpy integer that mujoco
>= 3.12 returns, so every ``Fetch*-v4`` fails when it is made. ``fix_joint_type_asserts`` probes
that failure on a one-joint model and, only where it occurs, replaces the four functions in that
module (in memory; site-packages is never edited) by ones that compare ``int(joint_type)``.

Observation mapping. Our tasks emit the reference's layout, so the policy is fed the reference's raw
``observation`` and ``desired_goal`` (float32) and applies its own input processing inside
``Policy.act`` (normaliser, goal relative to the achieved goal), exactly as in training:

  [0:3] grip site position        [3:6] object position        [6:9] object - grip
  [9:11] finger joints            [11:14] object Euler angles  [14:17] object - grip velocity
  [17:20] object angular velocity [20:23] grip velocity        [23:25] finger velocities
  (velocities in metres or radians per 0.04 s control step; Reach: grip, fingers, grip and finger
  velocity, 10 floats). achieved_goal = object position (grip position for Reach), desired_goal 3.

Actions: 4 floats clipped to [-1, 1] (``Policy.act`` clips); ``a[:3]`` moves the gripper target by
0.05 a metres, ``a[3]`` drives the fingers (ignored, fingers locked, in Reach, Push and Slide).

Same start. ``reference_start`` sets the reference, after its own ``reset``, to our task's sampled
start: the object's x-y (its height and orientation stay the reference's resting ones) and the goal,
both moved by the difference of the two simulators' gripper homes (and, in z, object rest heights);
the gripper starts at each simulator's home.

Differences measured here (traces from the same starts, ``--traces``; ``experiments/reference/RESULTS.md``):

- Every slot has the same meaning, frame (world coordinates, same table and homes within 0.4 mm) and
  unit in both: the scripted Push controller, fed each simulator's raw observation, succeeds in 300 of
  300 matched episodes in each (median final distance 0.004 m in both), and Reach's start
  observations agree within 0.4 mm.
- Floor, the largest difference: the reference's fingers meet the table with the grip site at z =
  0.417 to 0.420, and a downward command there drags them on it (a_y = 1 moves the grip 33 mm per
  step, with a_z = -0.3 24 mm, with a_z = -1 16 mm); ours clips the target at a workspace floor of
  0.408 and slides there freely (34 mm per step in all three). Trained policies press down: Push's
  strike is slower and its cube settles later in the reference, and Reach's lowest goals (below 0.42,
  about 11 %) are held at the final step far less often, the pressed gripper drifting 1 to 6 cm.
- Response to an action (``step_response``): a held a = 1 moves the grip 30 mm in the first step
  and 33.1 mm per step after (ours 30 and 33.9; commanded 50); on release it goes on 2.3 mm then
  back 0.3 mm (ours 3.7 and 0.4). Push's first step from home is 26 mm in the reference (its arm is
  still settling after reset: grip velocity -0.003 m per step in x in the first observation, ours 0).
- Beyond the arm's reach (a target about 0.2 m or more ahead of home in x) the reference arm creeps
  back some 7 cm in the 15 steps after release; ours keeps targets within the arm's reach and holds.
- At rest after reset the reference grip moves 2 to 3 mm in z over the first steps; ours does not.
  The locked fingers read 0.0004 to 0.0012 in slots [9:11] at the reference's start; ours read 0.
- Our Push table is by default a plane without edges (``table="plane"``); the reference's is a box
  a cube can be pushed off: a short-trained Push policy ends with the cube off the reference's table
  in 32 % of 300 matched episodes, never in ours (21 % with ``--env-options table=box``).
- Under the same scripted pushes (300 matched episodes) the reference's cube turns twice as much
  about z (mean |yaw|, slot 13: 0.13 rad against 0.06) and tilts less (slots 11, 12: 0.002 and 0.004
  rad against 0.008); every other slot's mean magnitude agrees within 21 % (the angular velocities differ most).
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import functools
import io
import json
import math
import os
import sys
import tempfile

import numpy as np

from splid_jax.common.errors import InvalidConfig

REFERENCE_IDS = {
    "reach": "FetchReach-v4",
    "push": "FetchPush-v4",
    "slide": "FetchSlide-v4",
    "pick_and_place": "FetchPickAndPlace-v4",
}
EXTRA = 'pip install -e ".[reference]"'
Z95 = 1.959963984540054  # the normal quantile of a two-sided 95 % interval


class EvaluationError(ValueError):
    """A user mistake the command reports in one line (exit code 2)."""


# ---- the run-time fix ------------------------------------------------------------------------------
_QPOS_SIZE = {0: 7, 1: 4, 2: 1, 3: 1}  # mjtJoint: free, ball, slide, hinge
_QVEL_SIZE = {0: 6, 1: 3, 2: 1, 3: 1}


def _joint(model, name: str, sizes: dict, address) -> tuple[int, int]:
    import mujoco

    joint_id = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name)
    assert joint_id != -1, f"Joint with name '{name}' is not part of the model!"
    start = int(address[joint_id])
    return start, start + sizes[int(model.jnt_type[joint_id])]


def _set_joint_qpos(model, data, name, value):
    start, end = _joint(model, name, _QPOS_SIZE, model.jnt_qposadr)
    data.qpos[start:end] = np.asarray(value)


def _set_joint_qvel(model, data, name, value):
    start, end = _joint(model, name, _QVEL_SIZE, model.jnt_dofadr)
    data.qvel[start:end] = np.asarray(value)


def _get_joint_qpos(model, data, name):
    start, end = _joint(model, name, _QPOS_SIZE, model.jnt_qposadr)
    return data.qpos[start:end].copy()


def _get_joint_qvel(model, data, name):
    start, end = _joint(model, name, _QVEL_SIZE, model.jnt_dofadr)
    return data.qvel[start:end].copy()


_PROBE = '<mujoco><worldbody><body><joint name="s" type="slide"/><geom size="0.1"/></body></worldbody></mujoco>'


def joint_getters_fail(mujoco_utils) -> bool:
    """Whether ``mujoco_utils.get_joint_qpos`` fails on a slide joint (mujoco >= 3.12's numpy joint type)."""
    import mujoco

    model = mujoco.MjModel.from_xml_string(_PROBE)
    try:
        mujoco_utils.get_joint_qpos(model, mujoco.MjData(model), "s")
    except AssertionError:
        return True
    return False


def fix_joint_type_asserts(mujoco_utils=None) -> bool:
    """Replace gymnasium-robotics' four joint getters/setters, in memory, by ones comparing
    ``int(joint_type)``, if they fail on this mujoco; True when it replaced them. The Fetch envs look
    them up through the module (``self._utils``), so the replacement reaches them."""
    if mujoco_utils is None:
        from gymnasium_robotics.utils import mujoco_utils
    if not joint_getters_fail(mujoco_utils):
        return False
    mujoco_utils.set_joint_qpos = _set_joint_qpos
    mujoco_utils.set_joint_qvel = _set_joint_qvel
    mujoco_utils.get_joint_qpos = _get_joint_qpos
    mujoco_utils.get_joint_qvel = _get_joint_qvel
    return True


# ---- the reference simulator -----------------------------------------------------------------------
def reference_id(task: str) -> str:
    if task not in REFERENCE_IDS:
        raise EvaluationError(
            f"task {task!r} has no reference simulator (only {', '.join(REFERENCE_IDS)} have a Fetch*-v4)"
        )
    return REFERENCE_IDS[task]


def import_reference():
    """gymnasium, its Fetch envs registered and the run-time fix applied where needed."""
    try:
        import gymnasium as gym

        with contextlib.redirect_stderr(io.StringIO()):  # a notice about its Adroit envs on import
            import gymnasium_robotics
    except ImportError:
        raise EvaluationError(f"the reference simulator is not installed: {EXTRA}") from None
    fix_joint_type_asserts()
    gym.register_envs(gymnasium_robotics)
    return gym


def make_reference(task: str):
    """The ``Fetch*-v4`` env matching our ``task``."""
    env_id = reference_id(task)
    return import_reference().make(env_id)


def reference_start(env, object_xy: np.ndarray | None, goal: np.ndarray) -> dict:
    """Put the reference env (already ``reset``) at a start given in its own coordinates: the object's
    x-y (its height, orientation and the gripper stay as its reset left them) and the goal. Returns
    its observation dict."""
    import mujoco

    u = env.unwrapped
    if object_xy is not None:
        from gymnasium_robotics.utils import mujoco_utils

        q = mujoco_utils.get_joint_qpos(u.model, u.data, "object0:joint")
        q[:2] = object_xy
        mujoco_utils.set_joint_qpos(u.model, u.data, "object0:joint", q)
        mujoco_utils.set_joint_qvel(u.model, u.data, "object0:joint", np.zeros(6))
    u.goal = np.asarray(goal, np.float64).copy()
    mujoco.mj_forward(u.model, u.data)
    return u._get_obs()


@dataclasses.dataclass(frozen=True)
class Episodes:
    """Batched episodes of one simulator, numpy: obs [E, T + 1, O], achieved [E, T + 1, 3],
    goal [E, 3], success [E, T] (after each step), actions [E, T, 4]."""

    obs: np.ndarray
    achieved: np.ndarray
    goal: np.ndarray
    success: np.ndarray
    actions: np.ndarray
    dt: float

    def summary(self) -> dict:
        return summarise(self.success.any(axis=1), self.success[:, -1], final_distance(self))


def final_distance(ep: Episodes) -> np.ndarray:
    return np.linalg.norm(ep.achieved[:, -1] - ep.goal, axis=-1)


def run_reference(task: str, act, episodes: int, seed: int, starts: dict | None = None,
                  batch: int = 50) -> Episodes:  # fmt: skip
    """``episodes`` of ``act(obs [B, O], goal [B, 3]) -> actions [B, 4]`` in the reference, ``batch``
    envs in lockstep (episodes never end early). Episode i resets with seed ``seed + i`` and, with
    ``starts`` (``our_starts``), is then put at our i-th start."""
    envs = [make_reference(task) for _ in range(min(batch, episodes))]
    steps = envs[0].spec.max_episode_steps
    out = {k: [] for k in ("obs", "achieved", "goal", "success", "actions")}
    for first in range(0, episodes, len(envs)):
        live = envs[: min(len(envs), episodes - first)]
        dicts = []
        for j, env in enumerate(live):
            o, _ = env.reset(seed=seed + first + j)
            if starts is not None:
                i = first + j
                xy = None if starts["object_xy"] is None else starts["object_xy"][i]
                o = reference_start(env, xy, starts["goal"][i])
            dicts.append(o)
        obs = [np.stack([d["observation"] for d in dicts])]
        ach = [np.stack([d["achieved_goal"] for d in dicts])]
        goal = np.stack([d["desired_goal"] for d in dicts])
        succ, acts = [], []
        for _ in range(steps):
            a = np.clip(np.asarray(act(obs[-1].astype(np.float32), goal.astype(np.float32)), np.float64), -1, 1)
            res = [env.step(a[j]) for j, env in enumerate(live)]
            obs.append(np.stack([r[0]["observation"] for r in res]))
            ach.append(np.stack([r[0]["achieved_goal"] for r in res]))
            succ.append([bool(r[4]["is_success"]) for r in res])
            acts.append(a)
        out["obs"].append(np.stack(obs, 1))
        out["achieved"].append(np.stack(ach, 1))
        out["goal"].append(goal)
        out["success"].append(np.array(succ).T)
        out["actions"].append(np.stack(acts, 1))
    u = envs[0].unwrapped
    dt = float(u.n_substeps * u.model.opt.timestep)
    for env in envs:
        env.close()
    return Episodes(**{k: np.concatenate(v) for k, v in out.items()}, dt=dt)


# ---- our task ----------------------------------------------------------------------------------------
def our_starts(env, key, episodes: int, reference_env=None):
    """Our task's starts (``jax.vmap(env.reset)`` of ``episodes`` keys split from ``key``, as the
    project's evaluation draws them): ``state``, and the object x-y and goal for ``reference_start``.
    Given a reset reference env, these are moved into its coordinates: x-y by the difference of the two
    grip homes; z by that of the object rest heights (tasks with an object: goals sit on the table or a
    lift above it) or of the grip homes (Reach)."""
    import jax

    start = jax.vmap(env.reset)(jax.random.split(key, episodes))
    goal = np.asarray(start.desired_goal, np.float64)
    xy = np.asarray(start.achieved_goal[:, :2], np.float64) if env.has_object else None
    if reference_env is not None:
        u, lay = reference_env.unwrapped, env.layout
        shift = np.asarray(u.initial_gripper_xpos[:3], np.float64) - np.asarray(lay.grip_home)
        if env.has_object:
            shift[2] = float(u.height_offset) - lay.object_rest_z
            xy = xy + shift[:2]
        goal = goal + shift
    return {"state": start, "object_xy": xy, "goal": goal}


def run_ours(env, act, start) -> Episodes:
    """Our task's episodes from the batched ``start`` under ``act(obs, goal) -> action`` (jax)."""
    import jax
    import jax.numpy as jnp

    from envs.base import step_batch

    @jax.jit
    def go(s0):
        def one(s, _):
            a = jnp.clip(act(s.obs, s.desired_goal), -1.0, 1.0)
            nxt = step_batch(env, s, a)
            return nxt, (nxt, a)

        _, (later, acts) = jax.lax.scan(one, s0, None, length=env.episode_length)
        return later, acts

    later, acts = go(start)
    cat = lambda a, b: np.concatenate([np.asarray(a)[:, None], np.moveaxis(np.asarray(b), 0, 1)], 1)  # noqa: E731
    return Episodes(
        obs=cat(start.obs, later.obs),
        achieved=cat(start.achieved_goal, later.achieved_goal),
        goal=np.asarray(start.desired_goal),
        success=np.moveaxis(np.asarray(later.success & ~later.invalid), 0, 1),
        actions=np.moveaxis(np.asarray(acts), 0, 1),
        dt=float(env.dt),
    )


# ---- statistics -------------------------------------------------------------------------------------
def wilson(successes: int, n: int, z: float = Z95) -> tuple[float, float]:
    """Wilson score interval of a binomial proportion: unlike the normal one it stays inside [0, 1]
    and is not empty at 0 or n successes."""
    if n <= 0:
        return (0.0, 1.0)
    p = successes / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    lo = 0.0 if successes == 0 else max(0.0, centre - half)
    return (lo, 1.0 if successes == n else min(1.0, centre + half))


def summarise(any_step, final_step, distance) -> dict:
    """Success at any and at the final step with Wilson 95 % intervals, and the median final distance."""
    any_step, final_step = np.asarray(any_step, bool), np.asarray(final_step, bool)
    n = int(any_step.size)
    out = {"episodes": n}
    for name, hits in (("success_any", any_step), ("success_final", final_step)):
        out[name] = float(hits.mean())
        out[name + "_ci95"] = list(wilson(int(hits.sum()), n))
    out["median_final_distance"] = float(np.median(distance))
    return out


# ---- a run's policy -----------------------------------------------------------------------------------
def sweep_member(run_dir: str) -> tuple[str, int, int] | None:
    """(sweep directory, member index, members) when ``run_dir`` is a member of a sweep, whose
    checkpoints the sweep directory holds, stacked over members."""
    parent = os.path.dirname(os.path.abspath(run_dir))
    path = os.path.join(parent, "sweep.json")
    if not os.path.isfile(path):
        return None
    with open(path) as fh:
        names = [m.get("run_dir") for m in json.load(fh).get("members", [])]
    name = os.path.basename(os.path.abspath(run_dir))
    return (parent, names.index(name), len(names)) if name in names else None


def _restore_member(cfg, sweep: tuple[str, int, int], step: int | None):
    """A sweep member's task, algorithm, state and step, sliced out of the sweep's stacked checkpoint
    (laid out as the sweep's own config builds it; members differ only in data, not in shapes)."""
    import jax

    from splid_jax.config import TrainConfig
    from splid_jax.learners.registry import make_algorithm
    from splid_jax.runtime import checkpoint
    from splid_jax.runtime.loop import make_env

    directory, index, members = sweep
    env = make_env(cfg.env, **cfg.env_overrides())  # the member's task, with any changed fields
    with open(os.path.join(directory, "sweep.json")) as fh:
        trainer = make_algorithm(TrainConfig.from_json(json.load(fh)["config"], run_dir=directory), env)
    like = jax.eval_shape(jax.vmap(trainer.init), jax.random.split(jax.random.PRNGKey(0), members))
    step, state, _ = checkpoint.restore(directory, like, step=step)
    return env, trainer, jax.tree.map(lambda x: x[index], state), step


def load_run(run_dir: str, step: int | None = None, env_options: str = ""):
    """(config, our task, algorithm, the policy's ``PolicyState``, step) of the run in ``run_dir``: a
    run of train, or a member of a sweep. ``env_options`` (``KEY=VALUE,...``) change our task's fields
    from the run's, e.g. ``table=box`` to put the reference's table edges in our task."""
    from splid_jax.common.networks import PolicyState
    from splid_jax.rollout import load_config, load_policy
    from splid_jax.runtime import checkpoint

    if not os.path.isdir(run_dir):
        raise EvaluationError(f"{run_dir} is not a directory")
    cfg = load_config(run_dir)
    if env_options:
        cfg = dataclasses.replace(cfg, env_options=",".join(filter(None, (cfg.env_options, env_options))))
    reference_id(cfg.env)
    sweep = sweep_member(run_dir) if checkpoint.latest_step(run_dir) is None else None
    if checkpoint.latest_step(run_dir) is None and (sweep is None or checkpoint.latest_step(sweep[0]) is None):
        raise EvaluationError(f"{run_dir} holds no checkpoint (train writes them in {run_dir}/checkpoints)")
    with contextlib.redirect_stdout(io.StringIO()):  # MJX prints a warp notice on import
        if sweep is None:
            env, trainer, state, step = load_policy(cfg, step)
        else:
            env, trainer, state, step = _restore_member(cfg, sweep, step)
    pstate = getattr(state, "policy", None)
    if not isinstance(pstate, PolicyState):
        raise EvaluationError(f"the checkpoint of {run_dir} holds no policy (no networks.PolicyState at .policy)")
    return cfg, env, trainer, pstate, step


def policy_act(trainer, pstate):
    """The deterministic policy as ``act(obs, goal) -> action``, jitted, batched over leading axes."""
    import jax

    return jax.jit(lambda o, g: trainer.policy.act(pstate, o, g))


def evaluate(run_dir: str, episodes: int = 300, seed: int = 0, step: int | None = None, env_options: str = "",
             loaded: tuple | None = None) -> dict:  # fmt: skip
    """The run's policy in the reference (its own resets, seeds ``seed`` ...) and in our task (the
    project's evaluation draw: ``rollout.rollout`` from ``PRNGKey(seed)``), ``episodes`` each.
    ``loaded``: what ``load_run`` gave, to load the checkpoint once."""
    import jax

    from splid_jax.rollout import rollout

    import_reference()  # a missing extra fails before any work
    cfg, env, trainer, pstate, step = loaded or load_run(run_dir, step, env_options)
    states = jax.jit(lambda ps, k: rollout(env, trainer, ps, k, episodes))(pstate, jax.random.PRNGKey(seed))
    succ = np.asarray(states.success[1:] & ~states.invalid[1:])
    dist = np.linalg.norm(np.asarray(states.achieved_goal[-1] - states.desired_goal[-1]), axis=-1)
    ours = summarise(succ.any(axis=0), succ[-1], dist)
    ref = run_reference(cfg.env, policy_act(trainer, pstate), episodes, seed).summary()
    return {
        "run_dir": run_dir,
        "algo": cfg.algo,
        "task": cfg.env,
        "reference": REFERENCE_IDS[cfg.env],
        "step": int(step),
        "seed": seed,
        "env_options": cfg.env_options,
        "ours": ours,
        "fetch": ref,
    }


# ---- traces -------------------------------------------------------------------------------------------
def trace_arrays(ep: Episodes, has_object: bool) -> dict:
    """Per step (T + 1): achieved-goal-to-goal distance, object speed (m/s; 0 for Reach), grip position."""
    dist = np.linalg.norm(ep.achieved - ep.goal[:, None], axis=-1)
    grip = ep.obs[..., 0:3]
    if has_object:
        speed = np.linalg.norm(ep.obs[..., 14:17] + ep.obs[..., 20:23], axis=-1) / ep.dt
    else:
        speed = np.zeros(dist.shape)
    return {"distance": dist, "object_speed": speed, "grip": grip, "success": ep.success}


SLOTS = {
    25: ("grip x", "grip y", "grip z", "object x", "object y", "object z", "rel x", "rel y", "rel z",
         "finger l", "finger r", "euler a", "euler b", "euler c", "rel vel x", "rel vel y", "rel vel z",
         "ang vel x", "ang vel y", "ang vel z", "grip vel x", "grip vel y", "grip vel z", "finger vel l",
         "finger vel r"),
    10: ("grip x", "grip y", "grip z", "finger l", "finger r", "grip vel x", "grip vel y", "grip vel z",
         "finger vel l", "finger vel r"),
}  # fmt: skip


def compare_slots(ours_obs: np.ndarray, fetch_obs: np.ndarray) -> dict:
    """Per observation slot, over every step of matched episodes ([E, T + 1, O] each): mean |value| in
    each simulator, mean |difference|, and the largest difference at the start (where both should agree)."""
    mean_abs = lambda x: np.abs(x).mean(axis=(0, 1))  # noqa: E731
    cols = (mean_abs(ours_obs), mean_abs(fetch_obs), mean_abs(ours_obs - fetch_obs),
            np.abs(ours_obs[:, 0] - fetch_obs[:, 0]).max(axis=0))  # fmt: skip
    keys = ("ours", "fetch", "diff", "start_diff")
    return {
        name: {k: float(c[i]) for k, c in zip(keys, cols, strict=True)}
        for i, name in enumerate(SLOTS[ours_obs.shape[-1]])
    }


def matched_episodes(task_env, task: str, act_jax, act_np, episodes: int, seed: int):
    """(ours, reference) ``Episodes`` from the same starts and goals: our task's ``reset`` draws
    them, the reference is put there after its own reset."""
    import jax

    probe = make_reference(task)
    probe.reset(seed=seed)
    starts = our_starts(task_env, jax.random.PRNGKey(seed), episodes, probe)
    probe.close()
    ours = run_ours(task_env, act_jax, starts["state"])
    ref = run_reference(task, act_np, episodes, seed, starts=starts)
    return ours, ref


def traces(task_env, task: str, act_jax, act_np, episodes: int, seed: int) -> dict:
    """Traces of both simulators from the same starts, keys ``ours_*`` and ``fetch_*`` ([E, T + 1]
    or [E, T + 1, 3]; ``*_success`` [E, T]) and the start goals."""
    ours, ref = matched_episodes(task_env, task, act_jax, act_np, episodes, seed)
    out = {"goal_ours": ours.goal, "goal_fetch": ref.goal, "ours_obs": ours.obs, "fetch_obs": ref.obs}
    for name, ep in (("ours", ours), ("fetch", ref)):
        for k, v in trace_arrays(ep, task_env.has_object).items():
            out[f"{name}_{k}"] = v
    return out


def split_by_final(tr: dict, sim: str) -> dict:
    """Median distance and object speed per step over the episodes that succeed at the final step and
    over those that do not (the ones that reached the goal at some step but lost it, separately)."""
    succ = tr[f"{sim}_success"]
    groups = {
        "final": succ[:, -1],
        "lost": succ.any(axis=1) & ~succ[:, -1],
        "never": ~succ.any(axis=1),
    }
    out = {}
    for name, mask in groups.items():
        out[name] = {
            "episodes": int(mask.sum()),
            "median_distance": np.median(tr[f"{sim}_distance"][mask], axis=0).tolist() if mask.any() else [],
            "median_object_speed": np.median(tr[f"{sim}_object_speed"][mask], axis=0).tolist() if mask.any() else [],
        }
    return out


@functools.cache
def jitted_step(task_env):
    """``jax.jit(task_env.step)``, compiled once per task for the response measurements."""
    import jax

    return jax.jit(task_env.step)


def grip_paths(task_env, task: str, actions) -> tuple[np.ndarray, np.ndarray]:
    """Grip positions [T + 1, 3] of (ours, reference) under the same ``actions`` [T, 4] from each
    one's home (our ``reset(PRNGKey(0))``, the reference's ``reset(seed=0)``)."""
    import jax
    import jax.numpy as jnp

    env = make_reference(task)
    o, _ = env.reset(seed=0)
    ref = [o["observation"][:3]]
    for a in actions:
        o, *_ = env.step(np.asarray(a, np.float64))
        ref.append(o["observation"][:3])
    env.close()
    s = task_env.reset(jax.random.PRNGKey(0))
    step = jitted_step(task_env)
    ours = [np.asarray(s.obs[:3])]
    for a in actions:
        s = step(s, jnp.asarray(a, jnp.float32))
        ours.append(np.asarray(s.obs[:3]))
    return np.array(ours, np.float64), np.array(ref, np.float64)


def step_response(task_env, task: str, action=(1.0, 0.0, 0.0, 0.0), hold: int = 10, release: int = 10) -> dict:
    """The grip's per-step displacement (m) in both simulators under ``action`` held ``hold`` steps then
    zero for ``release`` steps, and under zero action alone from home (drift at rest)."""
    held = np.concatenate([np.tile(np.asarray(action, np.float64), (hold, 1)), np.zeros((release, 4))])
    ours, ref = grip_paths(task_env, task, held)
    ours_rest, ref_rest = grip_paths(task_env, task, np.zeros((hold + release, 4)))
    return {
        "action": [float(x) for x in action],
        "hold": hold,
        "release": release,
        "commanded_per_step": (0.05 * np.asarray(action[:3], np.float64)).tolist(),
        "ours_step": np.diff(ours, axis=0).tolist(),
        "fetch_step": np.diff(ref, axis=0).tolist(),
        "ours_rest_step": np.diff(ours_rest, axis=0).tolist(),
        "fetch_rest_step": np.diff(ref_rest, axis=0).tolist(),
    }


def cube_slide(task_env, task: str, velocity=(0.5, 0.0), steps: int = 15) -> dict:
    """The object's free slide in both simulators: from each one's reset (seed 0, ``PRNGKey(0)``) the
    object is given the x-y ``velocity`` (m/s) and the gripper is held (zero action); per-step
    displacement (m) of the object along x-y, and the distance it travels."""
    import jax
    import jax.numpy as jnp

    v = np.array([*velocity, 0.0, 0.0, 0.0, 0.0])
    env = make_reference(task)
    from gymnasium_robotics.utils import mujoco_utils

    o, _ = env.reset(seed=0)
    u = env.unwrapped
    mujoco_utils.set_joint_qvel(u.model, u.data, "object0:joint", v)
    ref = [o["observation"][3:5]]
    for _ in range(steps):
        o, *_ = env.step(np.zeros(4))
        ref.append(o["observation"][3:5])
    env.close()
    s = task_env.reset(jax.random.PRNGKey(0))
    lay = task_env.layout
    qvel = s.physics.qvel.at[lay.object_v : lay.object_v + 6].set(jnp.asarray(v, s.physics.qvel.dtype))
    s = s.replace(physics=s.physics.replace(qvel=qvel))
    step = jitted_step(task_env)
    ours = [np.asarray(s.obs[3:5])]
    for _ in range(steps):
        s = step(s, jnp.zeros(4))
        ours.append(np.asarray(s.obs[3:5]))
    ours, ref = np.array(ours, np.float64), np.array(ref, np.float64)
    return {
        "velocity": [float(x) for x in velocity],
        "ours_step": np.linalg.norm(np.diff(ours, axis=0), axis=-1).tolist(),
        "fetch_step": np.linalg.norm(np.diff(ref, axis=0), axis=-1).tolist(),
        "ours_travel": float(np.linalg.norm(ours[-1] - ours[0])),
        "fetch_travel": float(np.linalg.norm(ref[-1] - ref[0])),
    }


def loaded_push(task_env, task: str, action=(1.0, 0.0, 0.0, 0.0), gap: float = 0.06, hold: int = 5,
                release: int = 5) -> dict:  # fmt: skip
    """The gripper pushing the object in both simulators: from each one's reset the object is put
    ``gap`` metres ahead of the grip (along the action's x-y direction), ``action`` is held ``hold``
    steps then zero for ``release``; per-step x-y displacement (m) of the grip and of the object."""
    import jax
    import jax.numpy as jnp

    a = np.asarray(action, np.float64)
    ahead = a[:2] / max(float(np.linalg.norm(a[:2])), 1e-9) * gap
    seq = np.concatenate([np.tile(a, (hold, 1)), np.zeros((release, 4))])
    env = make_reference(task)
    o, _ = env.reset(seed=0)
    o = reference_start(env, o["observation"][0:2] + ahead, o["desired_goal"])
    ref = [o["observation"][:5]]
    for x in seq:
        o, *_ = env.step(x)
        ref.append(o["observation"][:5])
    env.close()
    s = task_env.reset(jax.random.PRNGKey(0))
    q = task_env.layout.object_q
    qpos = s.physics.qpos.at[q : q + 2].set(s.obs[0:2] + jnp.asarray(ahead, s.obs.dtype))
    s = task_env.with_goal(s.replace(physics=s.physics.replace(qpos=qpos)), s.desired_goal)
    step = jitted_step(task_env)
    ours = [np.asarray(s.obs[:5])]
    for x in seq:
        s = step(s, jnp.asarray(x, jnp.float32))
        ours.append(np.asarray(s.obs[:5]))
    ours, ref = np.array(ours, np.float64), np.array(ref, np.float64)
    disp = lambda p, sl: np.linalg.norm(np.diff(p[:, sl], axis=0), axis=-1).tolist()  # noqa: E731
    return {"action": a.tolist(), "gap": gap, "hold": hold, "release": release,
            "ours_grip_step": disp(ours, slice(0, 2)), "fetch_grip_step": disp(ref, slice(0, 2)),
            "ours_object_step": disp(ours, slice(3, 5)), "fetch_object_step": disp(ref, slice(3, 5))}  # fmt: skip


RESPONSE_KEYS = ("ours_step", "fetch_step", "ours_rest_step", "fetch_rest_step")


# ---- command line -------------------------------------------------------------------------------------
def write_json_atomic(path: str, obj) -> None:
    folder = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(dir=folder, prefix=".reference-", suffix=".json")
    with os.fdopen(fd, "w") as fh:
        json.dump(obj, fh, indent=1)
    os.replace(tmp, path)


def _line(name: str, s: dict) -> str:
    lo_a, hi_a = s["success_any_ci95"]
    lo_f, hi_f = s["success_final_ci95"]
    return (
        f"{name:22s} any {s['success_any']:.3f} [{lo_a:.3f}, {hi_a:.3f}]  final {s['success_final']:.3f} "
        f"[{lo_f:.3f}, {hi_f:.3f}]  median final distance {s['median_final_distance']:.3f} m"
    )


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="python -m splid_jax.evaluate",
        description="Evaluate a run's deterministic policy in the reference simulator (Gymnasium-Robotics "
        "Fetch*-v4) and in our task, with 95 %% intervals.",
        allow_abbrev=False,
    )
    p.add_argument("run_dir", metavar="RUN_DIR", nargs="?", default=None)
    p.add_argument("--scripted", metavar="TASK", choices=sorted(REFERENCE_IDS), default=None,
                   help="instead of a run, the task's scripted controller (envs/fetch/scripted.py), from the same "
                   "starts and goals in both simulators: a check of the observation mapping")  # fmt: skip
    p.add_argument("--reference", action="store_true", help="run the policy in the matching Fetch*-v4 (needs "
                   f"{EXTRA})")  # fmt: skip
    p.add_argument("--episodes", type=int, default=300, help="episodes in each simulator (default: 300)")
    p.add_argument("--seed", type=int, default=0, help="seed of the episodes' starts and goals (default: 0)")
    p.add_argument("--step", type=int, default=None, help="checkpoint (iteration) to load (default: the newest)")
    p.add_argument("--env-options", default="", metavar="KEY=VALUE,...",
                   help="change our task's fields from the run's for its side of the comparison (e.g. table=box: "
                   "the reference's table, whose edges a pushed cube can fall off)")  # fmt: skip
    p.add_argument("--out", default=None, metavar="FILE.json",
                   help="default: RUN_DIR/reference.json (with --scripted: scripted-TASK.json)")  # fmt: skip
    p.add_argument("--traces", default=None, metavar="FILE.npz",
                   help="also trace both simulators from the same starts and goals (distance to goal, object "
                   "speed, grip position per step) and the grip's response to a held action")  # fmt: skip
    return p


def scripted(task: str, episodes: int, seed: int) -> tuple[dict, dict]:
    """The scripted controller of ``task`` from the same starts and goals in both simulators:
    (result, traces)."""
    import jax

    with contextlib.redirect_stdout(io.StringIO()):  # MJX prints a warp notice on import
        from envs.fetch.scripted import CONTROLLERS
        from splid_jax.runtime.loop import make_env
    import_reference()
    env = make_env(task)
    act = CONTROLLERS[task]
    tr = traces(env, task, act, jax.jit(act), episodes, seed)
    result = {"scripted": task, "task": task, "reference": REFERENCE_IDS[task], "seed": seed}
    for sim in ("ours", "fetch"):
        succ, dist = tr[f"{sim}_success"], tr[f"{sim}_distance"][:, -1]
        result[sim] = summarise(succ.any(axis=1), succ[:, -1], dist)
    return result, tr


def main(argv: list[str] | None = None) -> int:
    from splid_jax.runtime.checkpoint import CheckpointError

    p = build_parser()
    a = p.parse_args(argv)
    try:
        if not a.reference:
            raise EvaluationError("pass --reference (the evaluation in our task alone is what train reports)")
        if (a.run_dir is None) == (a.scripted is None):
            raise EvaluationError("give either RUN_DIR or --scripted TASK")
        if a.episodes < 1:
            raise EvaluationError(f"--episodes {a.episodes}: must be >= 1")
        if a.run_dir is not None and not os.path.isdir(a.run_dir):
            raise EvaluationError(f"{a.run_dir} is not a directory")
        out = a.out or (os.path.join(a.run_dir, "reference.json") if a.run_dir else f"scripted-{a.scripted}.json")
        if not os.path.isdir(os.path.dirname(os.path.abspath(out))):
            raise EvaluationError(f"--out {out}: its directory does not exist")
        if a.scripted:
            result, tr = scripted(a.scripted, a.episodes, a.seed)
            title = f"the scripted {a.scripted} controller, the same {a.episodes} starts in each"
        else:
            import_reference()  # a missing extra fails before the checkpoint is read
            loaded = load_run(a.run_dir, a.step, a.env_options)
            result = evaluate(a.run_dir, a.episodes, a.seed, loaded=loaded)
            what = f"{result['algo']} on {result['task']}, iteration {result['step']}"
            title = f"{a.run_dir} ({what}), {a.episodes} episodes each"
            if a.traces:
                cfg, env, trainer, pstate, _ = loaded
                pol = lambda o, g: trainer.policy.act(pstate, o, g)  # noqa: E731
                tr = traces(env, cfg.env, pol, policy_act(trainer, pstate), a.episodes, a.seed)
    except (EvaluationError, InvalidConfig, CheckpointError) as err:
        print(f"{p.prog}: error: {err}", file=sys.stderr)
        return 2
    print(title + ":")
    print(_line("ours (MJX)", result["ours"]))
    print(_line(result["reference"], result["fetch"]))
    if a.traces:
        from splid_jax.runtime.loop import make_env

        resp = step_response(make_env(result["task"]), result["task"])
        np.savez_compressed(a.traces, **tr, **{f"response_{k}": np.asarray(resp[k]) for k in RESPONSE_KEYS})
        result["traces"] = {"file": a.traces, "ours": split_by_final(tr, "ours"), "fetch": split_by_final(tr, "fetch")}
        result["step_response"] = resp
        result["slots"] = compare_slots(tr["ours_obs"], tr["fetch_obs"])
        print(f"traces: {a.traces} (same starts and goals in both; by final-step outcome in the JSON)")
    write_json_atomic(out, result)
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
