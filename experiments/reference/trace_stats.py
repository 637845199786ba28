"""Where each simulator loses the final step, from ``evaluate --reference --traces FILE.npz`` files: per
side, final-step success, episodes that reached the goal and lost it (of them: the cube off the table,
the cube still moving), cubes off the table and still moving at the final step, and the share of steps
with the grip below z 0.418 (the reference's fingers on its table).

    PYTHONPATH=. python experiments/reference/trace_stats.py 'DIR/s*.npz'
"""

from __future__ import annotations

import glob
import sys

import numpy as np

from envs.fetch.models import TABLE_TOP

MOVING = 0.02  # m/s
FINGERS_ON_TABLE = 0.418


def line(path: str) -> str:
    z = np.load(path)
    parts = []
    for side in ("ours", "fetch"):
        obs, speed, success, grip = (z[f"{side}_{k}"] for k in ("obs", "object_speed", "success", "grip"))
        fell, moving = obs[:, -1, 5] < TABLE_TOP, speed[:, -1] > MOVING
        lost = success.any(axis=1) & ~success[:, -1]
        parts.append(
            f"{side}: final {success[:, -1].mean():.3f} lost {lost.sum():3d} (fell {(lost & fell).sum():2d}, "
            f"moving {(lost & moving).sum():2d}) fell {fell.sum():2d} moving@50 {moving.mean():.2f} "
            f"grip<{FINGERS_ON_TABLE} {(grip[:, 1:, 2] < FINGERS_ON_TABLE).mean():.2f}"
        )
    return " | ".join(parts)


if __name__ == "__main__":
    for f in sorted(glob.glob(sys.argv[1])):
        print(f.rsplit("/", 1)[-1], line(f))
