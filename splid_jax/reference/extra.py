"""The optional extra (``pip install -e ".[reference]"``: gymnasium-robotics 1.4.2, beside our mujoco):
its import, the ``Fetch*-v4`` matching each task, and the run-time fix of its joint getters.

gymnasium-robotics 1.4.2's joint getters and setters (``utils/mujoco_utils.py``) assert
``joint_type in (mjJNT_HINGE, mjJNT_SLIDE)``, which is False for the numpy integer that mujoco >= 3.12
returns, so every ``Fetch*-v4`` fails when it is made. ``fix_joint_type_asserts`` probes that failure
on a one-joint model and, only where it occurs, replaces the four functions in that module (in memory;
site-packages is never edited) by ones that compare ``int(joint_type)``."""

from __future__ import annotations

import contextlib
import io

import numpy as np

REFERENCE_IDS = {
    "reach": "FetchReach-v4",
    "push": "FetchPush-v4",
    "slide": "FetchSlide-v4",
    "pick_and_place": "FetchPickAndPlace-v4",
}
EXTRA = 'pip install -e ".[reference]"'


class EvaluationError(ValueError):
    """A user mistake the command reports in one line (exit code 2)."""


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


# The last mujoco release gymnasium-robotics 1.4.2 runs unpatched. FetchSlide-v4's puck (a cylinder: MuJoCo's convex
# collider) plays differently after it (experiments/NOTES.md, "FetchSlide-v4 on two MuJoCo releases"); Push's and
# PickAndPlace's boxes do not.
UNPATCHED_MUJOCO = "3.11.0"


def versions() -> dict:
    """The releases the reference ran on, for the JSON beside its numbers."""
    from importlib.metadata import PackageNotFoundError, version

    import mujoco

    try:
        robotics = version("gymnasium-robotics")
    except PackageNotFoundError:
        robotics = None
    return {"mujoco": mujoco.__version__, "gymnasium_robotics": robotics}


def _release(text: str) -> tuple[int, ...]:
    return tuple(int(part) for part in text.split(".")[:3] if part.isdigit())


def release_notice(task: str, mujoco_version: str) -> str | None:
    """A line for a Slide evaluation whose reference ran on a MuJoCo newer than ``UNPATCHED_MUJOCO``."""
    if task != "slide" or _release(mujoco_version) <= _release(UNPATCHED_MUJOCO):
        return None
    return (
        f"note: FetchSlide-v4 ran on MuJoCo {mujoco_version}, whose puck contacts differ from those of "
        f"{UNPATCHED_MUJOCO}, the last release gymnasium-robotics 1.4.2 supports (--reference-python runs the "
        "reference in an environment of that release)"
    )


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
