"""A puck pushed by Slide's pads along the table, in our task and in FetchSlide-v4 from the same start: how long the
pads stay on the puck and how fast it leaves them. Learnt strikers part from the reference here: where the reference's
puck overshoots the goal, it leaves the pads within a few steps and faster, while ours is pushed along for many.

    python experiments/reference/pad_push.py --side ours|reference [--env-options K=V,...] [--speeds 0.6,0.8,1.0] \
        --out FILE.json

Each push lowers the pads to the table beside the grip's home (``DOWN`` steps), then drives at ``speed`` x full action
along +x and ``press`` along z (``PRESSES``: lightly down, or level) for ``PUSH`` steps and holds still for ``REST``
more; the puck starts ``AHEAD`` m ahead of the grip and ``dy`` aside. Per push (keyed "speed,dy,press"): the puck's
speed per step, the steps the grip stays within ``NEAR`` m of it, its peak speed and how far it went.
"""

from __future__ import annotations

import argparse
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", ".."))

from slide_on_puck import ours, reference  # noqa: E402

from splid_jax.common.values import parse_overrides  # noqa: E402
from splid_jax.reference.extra import import_reference  # noqa: E402

DOWN, PUSH, REST = 4, 8, 20
AHEAD, NEAR, DT = 0.08, 0.045, 0.04
SPEEDS, ASIDE, PRESSES = (0.6, 0.8, 1.0), (0.0, 0.01), (-0.3, 0.0)


def plan(speed: float, press: float) -> list[tuple[float, ...]]:
    return [(0, 0, -1, 0)] * DOWN + [(speed, 0, press, 0)] * PUSH + [(0, 0, 0, 0)] * REST


def measures(x: np.ndarray) -> dict:
    """``x``: grip xyz and puck xyz per step, [T + 1, 6]."""
    speed = np.linalg.norm(np.diff(x[:, 3:5], axis=0), axis=1) / DT
    near = np.linalg.norm(x[:, 0:2] - x[:, 3:5], axis=1) < NEAR
    moving = np.flatnonzero(speed > 0.05)
    return {"puck_speed": speed.round(3).tolist(), "near_steps": int(near.sum()),
            "peak_speed": round(float(speed.max()), 3), "launch_step": int(moving[0]) if moving.size else -1,
            "travel": round(float(np.linalg.norm(x[-1, 3:5] - x[0, 3:5])), 4)}  # fmt: skip


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--side", choices=("ours", "reference"), required=True)
    p.add_argument("--env-options", default="", help="our task's fields (the puck's place is computed from them)")
    p.add_argument("--speeds", default=",".join(map(str, SPEEDS)), help="fractions of full action, comma-separated")
    p.add_argument("--aside", default=",".join(map(str, ASIDE)), help="the puck's offsets across the push (m)")
    p.add_argument("--presses", default=",".join(map(str, PRESSES)), help="z actions while pushing")
    p.add_argument("--out", required=True)
    args = p.parse_args(argv)
    import envs

    env = envs.make("slide", **parse_overrides(args.env_options))
    if args.side == "reference":
        import_reference()
    play = ours if args.side == "ours" else reference
    result = {"side": args.side, "env_options": args.env_options, "pushes": {}}
    floats = lambda text: [float(v) for v in text.split(",")]  # noqa: E731
    for press in floats(args.presses):
        for speed in floats(args.speeds):
            for dy in floats(args.aside):
                m = measures(play(env, (AHEAD, dy), plan(speed, press)))
                result["pushes"][f"{speed},{dy},{press}"] = m
                print(f"press {press} speed {speed} aside {dy}: near {m['near_steps']} peak {m['peak_speed']} launch"
                      f" {m['launch_step']} travel {m['travel']}", flush=True)  # fmt: skip
    with open(args.out, "w") as fh:
        json.dump(result, fh, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
