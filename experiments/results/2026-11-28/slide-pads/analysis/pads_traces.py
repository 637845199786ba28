"""Where the pads' Slide policies lose the final step in FetchSlide-v4, from ``evaluate --reference --traces`` files
(the same starts and goals in both simulators): how often the gripper rests on the puck, how the puck leaves it,
how it slides after the last touch and where it ends along the start-to-goal line.

    PYTHONPATH=. python experiments/results/2026-11-28/slide-pads/analysis/pads_traces.py OUT.json A.npz B.npz ...

Definitions (grip site and puck centre from the observation, 0.04 s control steps):
- ``touch``: the pads' union in x-y (slide_fingers.PAD_*) within 3 mm of the puck's side and their bottoms below
  its top face; ``rest``: the grip 1.5 to 4 cm above the puck's centre and within 3 cm of its axis in x-y (the pads
  on the top face; the weld's light press leaves the grip 3.5 cm above it in both simulators);
- ``escape``: a resting step after which the gripper no longer rests and the puck moves faster than the grip by
  0.2 m/s within two steps; binned by the grip's x-y offset from the puck's axis (``h``) and by how diagonal it
  lies to the pads' axes (|sin 2 phi|, phi its angle);
- ``free slide``: steps with no touch in the step before, at or after, the puck on the table and faster than
  0.1 m/s: its loss of speed per second;
- ``puck_tilt``: from the observation's Euler angles about x and y, in degrees.
"""

from __future__ import annotations

import json
import sys

import numpy as np

DT = 0.04
RADIUS, PUCK_HALF = 0.025, 0.02
PAD_X, PAD_Y, PAD_BELOW = (-0.0145, 0.0125), (-0.0165, 0.015), 0.0185


def quant(x, qs=(0.1, 0.25, 0.5, 0.75, 0.9)) -> list:
    x = np.asarray(x, float)
    x = x[np.isfinite(x)]
    return [round(float(np.quantile(x, q)), 4) for q in qs] if x.size else []


def masks(obs: np.ndarray) -> dict:
    g, p = obs[..., 0:3], obs[..., 3:6]
    d = p - g
    gap = np.hypot(d[..., 0] - np.clip(d[..., 0], *PAD_X), d[..., 1] - np.clip(d[..., 1], *PAD_Y)) - RADIUS
    h = np.hypot(d[..., 0], d[..., 1])
    above = -d[..., 2]
    return {
        "touch": (gap < 0.003) & (g[..., 2] - PAD_BELOW < p[..., 2] + PUCK_HALF),
        "rest": (above > 0.015) & (above < 0.04) & (h < 0.03),
        "h": h,
        "diag": np.abs(np.sin(2 * np.arctan2(d[..., 1], d[..., 0]))),
        "above": above,
    }


def side_stats(z, side: str) -> dict:
    obs, goal, succ, speed = (z[f"{side}_obs"], z[f"goal_{side}"], z[f"{side}_success"], z[f"{side}_object_speed"])
    m = masks(obs)
    touch, rest, h, diag = m["touch"], m["rest"], m["h"], m["diag"]
    p = obs[..., 3:6]
    grip_speed = np.linalg.norm(obs[..., 20:23], axis=-1) / DT
    tilt = np.degrees(np.hypot(obs[..., 11], obs[..., 12]))
    tilt_step = np.abs(np.diff(tilt, axis=1))[rest[:, :-1] & rest[:, 1:]]
    n, t1 = touch.shape
    fell = p[:, -1, 2] < p[:, 0, 2] - 0.05
    final, reached = succ[:, -1], succ.any(axis=1)
    lost = reached & ~final
    u = goal[:, :2] - p[:, 0, :2]
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    rel = p[:, -1, :2] - goal[:, :2]
    along = np.where(fell, np.nan, (rel * u).sum(1))
    across = np.where(fell, np.nan, np.abs(rel[:, 0] * u[:, 1] - rel[:, 1] * u[:, 0]))
    last = np.array([np.flatnonzero(t).max() if t.any() else -1 for t in touch])
    after = (last >= 0) & (last < t1 - 1)
    slid = np.array([np.linalg.norm(p[i, -1, :2] - p[i, last[i], :2]) if after[i] else np.nan for i in range(n)])
    v_after = np.array([speed[i, last[i] + 1] if after[i] else np.nan for i in range(n)])
    lost_touching = sum(bool(touch[i, np.flatnonzero(succ[i]).max(): np.flatnonzero(succ[i]).max() + 3].any())
                        for i in np.flatnonzero(lost))  # fmt: skip
    decel, bins = [], {}
    for i in range(n):
        for t in range(1, t1 - 1):
            if (not touch[i, t - 1: t + 2].any() and speed[i, t] > 0.1 and speed[i, t + 1] > 0.02 and not fell[i]
                    and abs(p[i, t, 2] - p[i, 0, 2]) < 0.005):  # fmt: skip
                decel.append((speed[i, t] - speed[i, t + 1]) / DT)
            if rest[i, t]:
                key = ("axis" if diag[i, t] < 0.5 else "between" if diag[i, t] < 0.85 else "diagonal",
                       "h<0.015" if h[i, t] < 0.015 else "h>=0.015")  # fmt: skip
                esc = not rest[i, t + 1] and (speed[i, t + 1: t + 3] - grip_speed[i, t + 1: t + 3]).max() > 0.2
                c = bins.setdefault(", ".join(key), [0, 0])
                c[0] += 1
                c[1] += int(esc)
    return {
        "episodes": int(n),
        "success_any": float(reached.mean()),
        "success_final": float(final.mean()),
        "reached_then_lost": int(lost.sum()),
        "lost_with_the_pads_touching": int(lost_touching),
        "off_the_table": int(fell.sum()),
        "moving_at_the_end": int((speed[:, -1] > 0.02).sum()),
        "touch_share_of_steps": round(float(touch[:, 1:].mean()), 3),
        "rest_share_of_steps": round(float(rest[:, 1:].mean()), 3),
        "final_successes_resting_at_the_end": int((final & rest[:, -1]).sum()),
        "rest_height_q": quant(m["above"][rest]),
        "rest_offset_h_q": quant(h[rest]),
        "puck_tilt_deg_resting_q50_q90": quant(tilt[:, 1:][rest[:, 1:]], (0.5, 0.9)),
        "puck_tilt_change_deg_per_resting_step_q50_q90": quant(tilt_step, (0.5, 0.9)),
        "speed_after_last_touch_q": quant(v_after),
        "slid_after_last_touch_q": quant(slid),
        "along_q_past_goal_positive": quant(along),
        "across_q50_q90": quant(across, (0.5, 0.9)),
        "misses_short_over_5cm": int((~final & (along < -0.05)).sum()),
        "misses_long_over_5cm": int((~final & (along > 0.05)).sum()),
        "free_slide_deceleration_q25_50_75": quant(decel, (0.25, 0.5, 0.75)),
        "free_slide_samples": len(decel),
        "escape_per_resting_step": {k: {"steps": c[0], "escapes": c[1], "per_step": round(c[1] / c[0], 3)}
                                    for k, c in sorted(bins.items())},  # fmt: skip
    }


def main(argv: list[str]) -> int:
    out = {f.rsplit("/", 1)[-1]: {s: side_stats(np.load(f), s) for s in ("ours", "fetch")} for f in argv[1:]}
    with open(argv[0], "w") as fh:
        json.dump(out, fh, indent=1)
    for f, v in out.items():
        print(f)
        for k in v["ours"]:
            print(f"  {k:38s} ours {json.dumps(v['ours'][k])}\n  {'':38s} ref  {json.dumps(v['fetch'][k])}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
