"""How far Slide's puck goes down under ``slide_on_puck.py``'s press, in one simulator: the press probe measures
the grip against the puck, so a puck pressed into the table with the grip on it reads as a press like any other.
The reference's side alone, with a light press too, is
``results/2026-11-28/slide-pads/analysis/reference_puck_sink.py``; this one plays the same press in either
simulator, so our task is measured as the reference is.

    python experiments/reference/puck_sink.py --side ours [--env-options timestep=0.002,substeps=20] --out FILE.json
    REF311/bin/python experiments/reference/puck_sink.py --side reference --env-options finger=box,hand_pitch=0 \\
        --out FILE.json

Per offset (the fingers 0, 0.01 and 0.02 m behind the puck's centre) and control step: the puck's height from its
start (mm) and the grip's height above the puck's centre (m). ``--side reference`` runs FetchSlide-v4 under this
Python's MuJoCo (our task only places its puck, so options that MuJoCo cannot build may be dropped there).
"""

from __future__ import annotations

import argparse
import json
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(1, os.path.join(HERE, "..", ".."))

import slide_on_puck  # noqa: E402
from slide_press_probes import OFFSETS  # noqa: E402


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--side", choices=("ours", "reference"), required=True)
    p.add_argument("--env-options", default="", help="our task's fields, e.g. timestep=0.002,substeps=20")
    p.add_argument("--out", default=None)
    args = p.parse_args(argv)
    import mujoco

    import envs
    from splid_jax.common.values import parse_overrides

    if args.side == "reference":
        slide_on_puck.import_reference()
    env = envs.make("slide", **parse_overrides(args.env_options))
    play = slide_on_puck.reference if args.side == "reference" else slide_on_puck.ours
    result = {"side": args.side, "mujoco": mujoco.__version__, "env_options": args.env_options, "offsets": {}}
    for offset in OFFSETS:
        x = play(env, slide_on_puck.pressed_puck(offset), slide_on_puck.ACTIONS)
        sink = ((x[:, 5] - x[0, 5]) * 1000).round(1)
        result["offsets"][str(offset)] = {
            "puck_z_from_start_mm": sink.tolist(),
            "grip_above_puck": (x[:, 2] - x[:, 5]).round(4).tolist(),
            "lowest_mm": float(sink.min()),
        }
        print(f"{args.side} (MuJoCo {mujoco.__version__}) offset {offset}: lowest {sink.min():+.1f} mm;", sink[:20])
    if args.out:
        with open(args.out, "w") as fh:
            json.dump(result, fh, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
