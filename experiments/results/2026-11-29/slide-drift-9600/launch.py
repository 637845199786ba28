"""How a policy's strikes leave in both simulators, from ``evaluate --reference --traces`` files (the same starts,
goals and actions): per episode the puck's peak speed, its travel over the goal's distance and the grip's peak speed.

    PYTHONPATH=. python experiments/results/2026-11-29/slide-drift-9600/launch.py her-9601.npz ...
"""

from __future__ import annotations

import sys

import numpy as np

DT = 0.04  # a control step


def launch(z, side: str) -> dict[str, np.ndarray]:
    obs, goal = z[f"{side}_obs"], z[f"goal_{side}"]
    puck = obs[..., 3:5]
    travel = np.linalg.norm(puck[:, -1] - puck[:, 0], axis=-1)
    goal_distance = np.linalg.norm(goal[:, :2] - puck[:, 0], axis=-1)
    grip = z[f"{side}_grip"][..., :2]
    return {"peak": z[f"{side}_object_speed"].max(1), "travel_over_goal": travel / goal_distance,
            "grip_peak": np.linalg.norm(np.diff(grip, axis=1), axis=-1).max(1) / DT}  # fmt: skip


def main(paths: list[str]) -> None:
    for path in paths:
        z = np.load(path)
        ours, fetch = launch(z, "ours"), launch(z, "fetch")
        ratio = np.quantile(fetch["peak"] / np.maximum(ours["peak"], 1e-3), [0.1, 0.5, 0.9])
        print(f"{path}: puck peak speed median ours {np.median(ours['peak']):.3f}, there {np.median(fetch['peak']):.3f}"
              f" m/s; there / ours q10, q50, q90 {np.round(ratio, 3).tolist()}")  # fmt: skip
        for key in ("travel_over_goal", "grip_peak"):
            print(f"  {key} median ours {np.median(ours[key]):.3f}, there {np.median(fetch[key]):.3f}")


if __name__ == "__main__":
    main(sys.argv[1:])
