"""What sets FetchSlide-v4's drag when pressed: its hard press (``slide_on_puck.py``'s, at the puck's centre) and its
light press (``pads_rim_probe.py``'s, +x, 0.015 m behind the centre) with one part of its model changed at a time.

    PYTHONPATH=. python experiments/results/2026-11-28/slide-pads/analysis/reference_drag_knobs.py --out OUT.json

Knobs (``--knobs`` JSON, a list of objects): ``puck_table_mu`` (the puck's and the table's sliding friction, which
MuJoCo mixes by their maximum), ``pad_mu`` (the finger pads'), ``pad_condim``, ``puck_solref`` (the puck's and the
table's time constant), ``weld_tc`` (the mocap weld's), ``arm_damping`` (a scale of every joint's damping),
``cone`` (0 pyramidal, 1 elliptic) and ``impratio``. Per run: the hard press's grip height above the puck's centre
after the press and while dragged, the puck's and the grip's advance per step while dragged, the light press's
grip height and drag per step, and each probe's largest puck tilt.
"""

from __future__ import annotations

import argparse
import json
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.join(HERE, *[".."] * 5)
sys.path[:0] = [HERE, ROOT, os.path.join(ROOT, "experiments", "reference")]

KNOBS = [{}, {"puck_table_mu": 0.05}, {"puck_table_mu": 0.2}, {"pad_mu": 0.3}, {"pad_mu": 2.0}, {"pad_condim": 3},
         {"puck_solref": 0.01}, {"puck_solref": 0.04}, {"weld_tc": 0.01}, {"weld_tc": 0.03}, {"arm_damping": 0.0},
         {"cone": 1}, {"impratio": 10}]  # fmt: skip


def _set(m, knobs: dict) -> None:
    import mujoco

    geom = lambda name: mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, name)  # noqa: E731
    body = lambda i: mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, int(m.geom_bodyid[i])) or ""  # noqa: E731
    pads = [i for i in range(m.ngeom) if "finger" in body(i)]
    puck_table = [geom("object0"), geom("table0")]
    for k, v in knobs.items():
        if k == "puck_table_mu":
            m.geom_friction[puck_table, 0] = v
        elif k == "pad_mu":
            m.geom_friction[pads, 0] = v
        elif k == "pad_condim":
            m.geom_condim[pads] = v
        elif k == "puck_solref":
            m.geom_solref[puck_table, 0] = v
        elif k == "weld_tc":
            m.eq_solref[:, 0] = v
        elif k == "arm_damping":
            m.dof_damping[:] *= v
        elif k == "cone":
            m.opt.cone = v
        elif k == "impratio":
            m.opt.impratio = v
        else:
            raise SystemExit(f"unknown knob {k!r}")


def trace(knobs: dict, acts: list, u, offset: float) -> np.ndarray:
    from splid_jax.reference.extra import make_reference
    from splid_jax.reference.mapping import reference_start

    r = make_reference("slide")
    r.reset(seed=0)
    _set(r.unwrapped.model, knobs)
    xy = np.asarray(r.unwrapped.initial_gripper_xpos[:2]) + (0.04 + offset) * np.asarray(u)
    out = [reference_start(r, xy, np.asarray(r.unwrapped.goal))["observation"]]
    for a in acts:
        out.append(r.step(np.asarray(a, np.float64))[0]["observation"])
    r.close()
    return np.array(out, np.float64)


def probe(knobs: dict) -> dict:
    import pads_rim_probe as rim
    import slide_on_puck
    import slide_press_probes as press

    u = np.array([1.0, 0.0])
    x = trace(knobs, slide_on_puck.ACTIONS, u, 0.0)
    hard = {**press.measures(x[:, :6]), "grip_per_step": round(float((x[18, 0] - x[10, 0]) / 8), 4),
            "puck_tilt_deg_max": rim.measures(x, u)["puck_tilt_deg_max_pressed"]}  # fmt: skip
    light = rim.measures(trace(knobs, rim.actions(u, -0.25, 0.5), u, 0.015), u)
    return {"knobs": knobs, "hard": hard, "light": light}


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--knobs", default=None, help="a JSON list of knob objects (default: KNOBS)")
    p.add_argument("--out", default=None)
    args = p.parse_args(argv)
    from splid_jax.reference.extra import import_reference

    import_reference()
    import mujoco

    rows = []
    for knobs in json.loads(args.knobs) if args.knobs else KNOBS:
        rows.append(probe(knobs))
        h, lt = rows[-1]["hard"], rows[-1]["light"]
        print(
            json.dumps(knobs),
            f"hard: on {h['grip_on_puck']} dragging {h['grip_dragging']} puck {h['drag_per_step']}"
            f" grip {h['grip_per_step']} | light: {lt['dragging']} {lt['drag_per_step']}",
            flush=True,
        )
    if args.out:
        with open(args.out, "w") as fh:
            json.dump({"mujoco": mujoco.__version__, "rows": rows}, fh, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
