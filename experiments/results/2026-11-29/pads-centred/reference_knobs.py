"""A run's Slide policy in FetchSlide-v4 with one part of the reference changed, 100 episodes from the reference's own
starts (seed 0): success. Run under the reference's interpreter (MuJoCo 3.11.0, gymnasium-robotics 1.4.2):

    PYTHONPATH=. REF/bin/python experiments/results/2026-11-29/pads-centred/reference_knobs.py RUN_DIR KNOB

KNOB: none, arm_damping0 (the arm's seven joints undamped), fingers_stiff (finger joint damping 1e6), weld_stiff /
weld_0.01 / weld_soft (the mocap weld's solref time constant 0.005 / 0.01 / 0.04 instead of 0.02), table_stiff (the
table's contacts at solref 0.004 1, solimp 0.99 0.99 0.001, its side of every mix: a pressed puck cannot sink).
"""
import json
import sys

import splid_jax.reference.episodes as E
from splid_jax.reference.extra import import_reference
from splid_jax.reference.extra import make_reference as make
from splid_jax.reference.policy import load_run, reference_here
from splid_jax.reference.side import loadable

run_dir, knob = sys.argv[1], sys.argv[2]
ARM = ("shoulder_pan", "shoulder_lift", "upperarm_roll", "elbow_flex", "forearm_roll", "wrist_flex", "wrist_roll")

def patched(task):
    env = make(task)
    m = env.unwrapped.model
    if knob == "weld_stiff":
        m.eq_solref[0] = [0.005, 1.0]
    elif knob == "arm_damping0":
        for j in ARM:
            m.dof_damping[m.jnt_dofadr[m.joint(f"robot0:{j}_joint").id]] = 0.0
    elif knob == "weld_soft":
        m.eq_solref[0] = [0.04, 1.0]
    elif knob == "fingers_stiff":
        for side in ("r", "l"):
            m.dof_damping[m.jnt_dofadr[m.joint(f"robot0:{side}_gripper_finger_joint").id]] = 1e6
    elif knob == "weld_0.01":
        m.eq_solref[0] = [0.01, 1.0]
    elif knob == "table_stiff":
        t = m.geom("table0").id
        m.geom_solref[t], m.geom_solimp[t, :3], m.geom_solmix[t] = [0.004, 1.0], [0.99, 0.99, 0.001], 1e6
    elif knob != "none":
        raise SystemExit(f"unknown knob {knob}")
    return env

E.make_reference = patched
import_reference()
cfg, env, policy, pstate, _ = load_run(run_dir, adapt=loadable)
fetch, ran_on = reference_here(cfg, policy, pstate, 100, 0)
row = {"run": run_dir.rsplit("/", 1)[-1], "knob": knob, "success_any": fetch["success_any"]}
print(json.dumps({**row, "success_final": fetch["success_final"], **ran_on}))
