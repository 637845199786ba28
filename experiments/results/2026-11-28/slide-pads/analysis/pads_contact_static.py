"""One reference finger pad pressed 3.5 mm into the puck's top (the learnt policies' light press), its grip site
``s`` behind the puck's axis along +x or the diagonal, the pad or the puck tilted 0.05 rad or not: MuJoCo C's contacts
(its native convex collider, FetchSlide's default) beside ours (``envs/box_cylinder.py``), with
``tests/envs/test_box_cylinder.py``'s helpers. Prints per case the largest horizontal component of the normals and
the deepest and shallowest depth (mm) of each.

    PYTHONPATH=. python experiments/results/2026-11-28/slide-pads/analysis/pads_contact_static.py
"""

from __future__ import annotations

import os
import sys

import numpy as np

ROOT = os.path.join(os.path.dirname(__file__), *[".."] * 5)
sys.path[:0] = [ROOT, os.path.join(ROOT, "tests", "envs")]

from test_box_cylinder import _contacts, _mujoco  # noqa: E402

PADS = {"pad_r": (-0.001, 0.008), "pad_l": (-0.001, -0.0095)}  # slide_fingers.PAD_CENTERS
Z = 0.02 + 0.0385 - 0.0035  # the pad's centre: its bottom 3.5 mm into the top face


def summary(dist, normal) -> str:
    if not len(dist):
        return "none"
    horiz = np.abs(normal[:, :2]).max()
    return f"{len(dist)} pts, horiz {horiz:.2f}, depth {-dist.max() * 1e3:.1f}-{-dist.min() * 1e3:.1f}"


def main() -> int:
    for name, u in (("+x", np.array([1.0, 0.0])), ("diag", np.array([0.7071, 0.7071]))):
        perp = np.array([-u[1], u[0]])
        for s in (0.015, 0.02, 0.0225, 0.025, 0.0275):
            for tilt in ("none", "pad", "puck"):
                e = tuple(0.05 * perp) + (0.0,)
                kw = {} if tilt == "none" else {"box_euler": e} if tilt == "pad" else {"cyl_euler": e}
                for pad, c in PADS.items():
                    pos = (-s * u[0] + c[0], -s * u[1] + c[1], Z)
                    dist, _, normal, poses = _mujoco(pos, **kw)
                    ours = _contacts(_mujoco(pos, **kw)[3])
                    print(f"{name:4s} s={s:.4f} tilt={tilt:4s} {pad}: C {summary(dist, normal):34s} "
                          f"ours {summary(ours[0], ours[2])}")  # fmt: skip
    return 0


if __name__ == "__main__":
    sys.exit(main())
