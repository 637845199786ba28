"""Where FetchSlide-v4's pressed puck and pads are, on the MuJoCo this runs on: per control step, the puck's centre
and the grip's height above the table top, under ``slide_on_puck.py``'s hard press (at the centre and 0.01 m behind)
and ``pads_rim_probe.py``'s light press (+x, 0 and 0.015 m behind); and the pads pressed on the bare table (the puck
0.3 m ahead), the grip's advance per step. With ``--env-options``, the table press in our Slide too.

    PYTHONPATH=. python experiments/results/2026-11-28/slide-pads/analysis/reference_puck_sink.py --out OUT.json

The puck rests with its centre 0.02 above the table top, the grip 0.0185 above its pads' bottom.
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

TABLE_TOP = 0.4  # FetchSlide-v4's table top


def table_press(x: np.ndarray) -> dict:
    """The grip's height above the table top and advance per step while pressed and dragged (steps 11 to 18)."""
    return {
        "grip_above_table": round(float(x[11:19, 2].mean() - TABLE_TOP), 4),
        "grip_per_step": round(float((x[18, 0] - x[10, 0]) / 8), 4),
    }


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--env-options", action="append", default=[], help="also our Slide's table press (repeatable)")
    p.add_argument("--out", default=None)
    args = p.parse_args(argv)
    import mujoco
    import pads_rim_probe as rim
    import reference_drag_knobs as knobs
    import slide_on_puck

    from splid_jax.reference.extra import import_reference

    import_reference()
    u = np.array([1.0, 0.0])
    probes = {
        "hard 0": (slide_on_puck.ACTIONS, 0.0),
        "hard 0.01": (slide_on_puck.ACTIONS, 0.01),
        "light 0": (rim.actions(u, -0.25, 0.5), 0.0),
        "light 0.015": (rim.actions(u, -0.25, 0.5), 0.015),
    }
    out = {"mujoco": mujoco.__version__, "reference": {}, "table_press": {}}
    for name, (acts, offset) in probes.items():
        x = knobs.trace({}, acts, u, offset)
        out["reference"][name] = {
            "puck_above_table": (x[:, 5] - TABLE_TOP).round(4).tolist(),
            "grip_above_table": (x[:, 2] - TABLE_TOP).round(4).tolist(),
        }
        print(name, "puck centre above the table top, steps 6 to 18:", out["reference"][name]["puck_above_table"][6:19])
    for press in (-0.25, -1.0):
        acts = rim.actions(u, press, 0.5)
        row = {"reference": table_press(knobs.trace({}, acts, u, 0.3))}
        for options in args.env_options:
            import jax

            import envs
            from splid_jax.common.values import parse_overrides

            env = envs.make("slide", **parse_overrides(options))
            x = rim.ours(env, jax.jit(env.step), u, 0.3, acts)
            row[options] = table_press(np.concatenate([x[:, :2], x[:, 2:3] - env.layout.object_rest_z + 0.02
                                                       + TABLE_TOP, x[:, 3:]], axis=1))  # fmt: skip
        out["table_press"][str(press)] = row
        print("table press", press, row)
    if args.out:
        with open(args.out, "w") as fh:
            json.dump(out, fh, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
