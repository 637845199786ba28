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

The modules, one job each: ``extra`` (the optional extra's import, the ``Fetch*-v4`` of each task and
the run-time fix), ``mapping`` (matched starts), ``episodes`` (running both simulators, Wilson
intervals), ``tracing`` (traces from the same starts, slots compared), ``response`` (the physical-response
measurements), ``policy`` (a run's policy, sweep members included) and ``cli``. Their public names are
reachable from this package too, loaded on first use.
"""

from __future__ import annotations

from splid_jax.common.lazy import lazy_names

_HOMES = {
    "splid_jax.reference.extra": (
        "EXTRA",
        "REFERENCE_IDS",
        "EvaluationError",
        "fix_joint_type_asserts",
        "import_reference",
        "joint_getters_fail",
        "make_reference",
        "reference_id",
    ),
    "splid_jax.reference.mapping": ("load_starts", "our_starts", "reference_start", "save_starts", "shifted"),
    "splid_jax.reference.episodes": (
        "Z95",
        "Episodes",
        "final_distance",
        "matched_episodes",
        "matched_reference",
        "ours_from_starts",
        "run_ours",
        "run_reference",
        "summarise",
        "wilson",
    ),
    "splid_jax.reference.tracing": (
        "SLOTS",
        "compare_slots",
        "split_by_final",
        "trace_arrays",
        "traces",
        "traces_of",
    ),
    "splid_jax.reference.response": (
        "RESPONSE_KEYS",
        "cube_slide",
        "grip_paths",
        "jitted_step",
        "loaded_push",
        "step_response",
    ),
    "splid_jax.reference.policy": ("evaluate", "load_run", "policy_act", "sweep_member"),
    "splid_jax.reference.cli": ("build_parser", "main", "scripted", "write_result"),
}
__getattr__, __dir__, __all__ = lazy_names(__name__, _HOMES)
