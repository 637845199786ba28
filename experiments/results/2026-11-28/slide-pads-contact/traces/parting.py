"""Where a Slide policy's episodes part between our task and FetchSlide-v4, from ``evaluate --reference --traces``
files (the same starts, goals and policy in both simulators), episode by episode.

    PYTHONPATH=. python experiments/results/2026-11-28/slide-pads-contact/traces/parting.py OUT.json NAME=T.npz ...

Per control step (0.04 s) of each simulator, from the observation (grip site, puck centre, their velocities):
- ``touch``: the pads' union in x-y within 3 mm of the puck's side and their bottoms below its top face;
  ``on``: the grip less than 5 cm above the puck's centre and within 3 cm of its axis (the pads on its top face, or
  over a puck pressed into the table); ``sunk``: the puck's centre more than 5 mm below its resting height (3.11's
  puck drops into the table box when pressed); ``tipped``: the puck tilted more than 30 degrees;
- the phase: ``approach`` before the first touch or ``on``, then ``on``, ``push`` (touching, not on), ``slide`` (the
  puck faster than 0.05 m/s) or ``still``;
- ``carry``: the puck's x-y advance per step while ``on`` at both ends of the step, against the grip's;
- ``escapes`` and ``leave`` rates: ``holding``;
- the parting step: the first step where the two simulators' pucks or grips are more than 1 cm apart in x-y.
Outcomes of a failed final step: ``off`` (the puck fell), ``long`` / ``short`` (more than 5 cm past / before the goal
along the start-to-goal line), ``wide`` (otherwise). ``lost``: reached at some step, not at the final one.
"""

from __future__ import annotations

import json
import sys

import numpy as np

DT, RADIUS, PUCK_HALF, REST_Z = 0.04, 0.025, 0.02, 0.42
PAD_X, PAD_Y, PAD_BELOW = (-0.0145, 0.0125), (-0.0165, 0.015), 0.0185
PHASES = ("approach", "on", "push", "slide", "still")


def q(x, qs=(0.1, 0.5, 0.9)) -> list:
    x = np.asarray(x, float)
    x = x[np.isfinite(x)]
    return [round(float(np.quantile(x, v)), 4) for v in qs] if x.size else []


def per_step(obs: np.ndarray, goal: np.ndarray) -> dict:
    g, p = obs[..., 0:3], obs[..., 3:6]
    d = p - g
    gap = np.hypot(d[..., 0] - np.clip(d[..., 0], *PAD_X), d[..., 1] - np.clip(d[..., 1], *PAD_Y)) - RADIUS
    h, above = np.hypot(d[..., 0], d[..., 1]), -d[..., 2]
    touch = (gap < 0.003) & (g[..., 2] - PAD_BELOW < p[..., 2] + PUCK_HALF)
    on = (above < 0.05) & (h < 0.03)
    pv = (obs[..., 14:17] + obs[..., 20:23]) / DT
    speed = np.hypot(pv[..., 0], pv[..., 1])
    met = touch | on
    first = np.where(met.any(1), met.argmax(1), touch.shape[1])
    phase = np.where(on, 1, np.where(touch, 2, np.where(speed > 0.05, 3, 4)))
    phase[np.arange(touch.shape[1])[None] < first[:, None]] = 0
    u = goal[:, :2] - p[:, 0, :2]
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    rel = p[..., :2] - goal[:, None, :2]
    return {"g": g, "p": p, "touch": touch | on, "on": on, "sunk": p[..., 2] < REST_Z - 0.005, "speed": speed,
            "phase": phase, "along": (rel * u[:, None]).sum(-1), "dist": np.linalg.norm(p - goal[:, None], axis=-1),
            "tilt": np.degrees(np.hypot(obs[..., 11], obs[..., 12]))}  # fmt: skip


def free_decel(s: dict) -> np.ndarray:
    """The puck's loss of speed per second over steps with nothing on or touching it (the step before, at and after),
    upright, on the table and faster than 0.1 m/s."""
    free = ~(s["touch"][:, :-2] | s["touch"][:, 1:-1] | s["touch"][:, 2:])
    v0, v1 = s["speed"][:, 1:-1], s["speed"][:, 2:]
    up = (np.abs(s["p"][:, 1:-1, 2] - REST_Z) < 0.003) & (s["tilt"][:, 1:-1] < 5)
    return ((v0 - v1) / DT)[free & up & (v0 > 0.1) & (v1 > 0.02)]


def holding(s: dict, u: np.ndarray) -> dict:
    """How the pads keep the puck. ``escapes``: steps ``on`` after which the pads are off it and the puck is 0.2 m/s
    faster than the grip within two steps, per ``on`` step; ``leave``: per step at the goal (success), the share
    after which the next step is not, with the pads on the puck and with nothing touching it."""
    grip_speed = np.linalg.norm(np.diff(s["g"][..., :2], axis=1), axis=-1) / DT
    on, fast = s["on"], s["speed"][:, 1:] - grip_speed > 0.2
    esc = on[:, :-2] & ~on[:, 1:-1] & (fast[:, :-1] | fast[:, 1:])
    succ = np.concatenate([np.zeros((len(u), 1), bool), u], 1)  # aligned with the observations
    inn, nxt = succ[:, 1:-1], succ[:, 2:]
    at_goal_on, at_goal_free = inn & on[:, 1:-1], inn & ~s["touch"][:, 1:-1]
    return {
        "on_steps": int(on[:, :-2].sum()),
        "escapes_per_on_step": round(float(esc.sum() / max(on[:, :-2].sum(), 1)), 4),
        "on_steps_sunk_share": round(float((on & s["sunk"]).sum() / max(on.sum(), 1)), 3),
        "at_goal_on_steps": int(at_goal_on.sum()),
        "leave_per_at_goal_on_step": round(float((at_goal_on & ~nxt).sum() / max(at_goal_on.sum(), 1)), 4),
        "at_goal_free_steps": int(at_goal_free.sum()),
        "leave_per_at_goal_free_step": round(float((at_goal_free & ~nxt).sum() / max(at_goal_free.sum(), 1)), 4),
    }


def outcome(s: dict, succ: np.ndarray, i: int) -> str:
    if succ[i, -1]:
        return "final"
    if s["p"][i, -1, 2] < REST_Z - 0.05:
        return "off"
    a = s["along"][i, -1]
    return "long" if a > 0.05 else "short" if a < -0.05 else "wide"


def last_touch(s: dict, i: int) -> dict:
    """The puck after the pads last touched it: its speed, how far it then slid, its distance to the goal then."""
    t = np.flatnonzero(s["touch"][i])
    if not t.size or t[-1] >= s["touch"].shape[1] - 1:
        return {"step": int(t[-1]) if t.size else -1, "speed": np.nan, "slid": 0.0, "dist": np.nan}
    k = int(t[-1])
    return {"step": k, "speed": float(s["speed"][i, k + 1]), "dist": float(s["dist"][i, k]),
            "slid": float(np.linalg.norm(s["p"][i, -1, :2] - s["p"][i, k, :2]))}  # fmt: skip


def analyse(z) -> dict:
    so, sr = per_step(z["ours_obs"], z["goal_ours"]), per_step(z["fetch_obs"], z["goal_fetch"])
    uo, ur = z["ours_success"], z["fetch_success"]
    n, t1 = so["touch"].shape
    apart = (np.linalg.norm(so["p"][..., :2] - sr["p"][..., :2], axis=-1) > 0.01) | (
        np.linalg.norm(so["g"][..., :2] - sr["g"][..., :2], axis=-1) > 0.01)  # fmt: skip
    part = np.where(apart.any(1), apart.argmax(1), t1)
    out = {"episodes": int(n), "ours_final": float(uo[:, -1].mean()), "fetch_final": float(ur[:, -1].mean()),
           "ours_any": float(uo.any(1).mean()), "fetch_any": float(ur.any(1).mean()),
           "part_step_q_all": q(part), "never_part": int((part == t1).sum()),
           "ours_phase_before_part_all": {p: int(sum(so["phase"][i, max(part[i] - 1, 0)] == j for i in range(n)))
                                          for j, p in enumerate(PHASES)}}  # fmt: skip
    for name, s, u in (("ours", so, uo), ("fetch", sr, ur)):
        lt = [last_touch(s, i) for i in range(n)]
        fin = u[:, -1]
        goal_on = s["on"] & (s["dist"] < 0.05)
        carry = s["on"][:, :-1] & s["on"][:, 1:]
        step_p = np.linalg.norm(np.diff(s["p"][..., :2], axis=1), axis=-1)
        step_g = np.linalg.norm(np.diff(s["g"][..., :2], axis=1), axis=-1)
        out[name] = {
            "outcomes": {
                k: int(sum(outcome(s, u, i) == k for i in range(n))) for k in ("final", "long", "short", "wide", "off")
            },  # fmt: skip
            "lost": int((u.any(1) & ~fin).sum()),
            "phase_share": {p: round(float((s["phase"][:, 1:] == j).mean()), 3) for j, p in enumerate(PHASES)},
            "final_on_at_end": int((fin & s["on"][:, -1]).sum()),
            "final_touching_at_end": int((fin & s["touch"][:, -1]).sum()),
            "on_steps_within_5cm_of_goal_per_episode": round(float(goal_on.sum() / n), 2),
            "steps_sunk_share": round(float(s["sunk"][:, 1:].mean()), 3),
            "episodes_ever_sunk": int(s["sunk"].any(1).sum()),
            "episodes_ever_tipped": int((s["tilt"] > 30).any(1).sum()),
            "puck_above_rest_while_on_q": q(s["p"][..., 2][s["on"]] - REST_Z),
            "grip_above_table_while_on_q": q(s["g"][..., 2][s["on"]] - REST_Z + PUCK_HALF),
            "carry_puck_step_q": q(step_p[carry]),
            "carry_grip_step_q": q(step_g[carry]),
            "carry_ratio_median": round(float(np.median(step_p[carry]) / np.median(step_g[carry])), 3),
            "free_slide_deceleration_q": q(free_decel(s), (0.25, 0.5, 0.75)),
            **holding(s, u),
            "speed_after_last_touch_q": q([x["speed"] for x in lt]),
            "slid_after_last_touch_q": q([x["slid"] for x in lt]),
            "final_along_q": q([s["along"][i, -1] for i in range(n) if outcome(s, u, i) != "off"]),
        }
    key = uo[:, -1] & ~ur[:, -1]
    rows = []
    for i in np.flatnonzero(key):
        k = int(part[i])
        lo, lr = last_touch(so, i), last_touch(sr, i)
        after = slice(k, t1)
        rows.append({
            "episode": int(i), "part_step": k,
            "phase_ours": PHASES[so["phase"][i, min(k, t1 - 1)]], "phase_fetch": PHASES[sr["phase"][i, min(k, t1 - 1)]],
            "ours_dist_at_part": round(float(so["dist"][i, min(k, t1 - 1)]), 3),
            "fetch_outcome": outcome(sr, ur, i), "fetch_reached": bool(ur[i].any()),
            "ours_on_steps": int(so["on"][i].sum()), "fetch_on_steps": int(sr["on"][i].sum()),
            "ours_on_at_end": bool(so["on"][i, -1]), "fetch_sunk_steps": int(sr["sunk"][i].sum()),
            "fetch_sunk_steps_after_part": int(sr["sunk"][i, after].sum()),
            "fetch_first_sunk_minus_part": int(sr["sunk"][i].argmax() - k) if sr["sunk"][i].any() else None,
            "fetch_tipped": bool((sr["tilt"][i] > 30).any()),
            "ours_last_touch": {k2: round(v, 3) for k2, v in lo.items()},
            "fetch_last_touch": {k2: round(v, 3) for k2, v in lr.items()},
            "fetch_final_along": round(float(sr["along"][i, -1]), 3),
            "fetch_max_speed_after_part": round(float(sr["speed"][i, after].max()), 3),
            "ours_max_speed_after_part": round(float(so["speed"][i, after].max()), 3),
        })  # fmt: skip
    out["ours_final_fetch_not"] = {
        "episodes": len(rows),
        "part_step_q": q([r["part_step"] for r in rows]),
        "phase_at_part_ours": {p: sum(r["phase_ours"] == p for r in rows) for p in PHASES},
        "phase_at_part_fetch": {p: sum(r["phase_fetch"] == p for r in rows) for p in PHASES},
        "fetch_outcome": {k: sum(r["fetch_outcome"] == k for r in rows) for k in ("long", "short", "wide", "off")},
        "fetch_reached_then_lost": sum(r["fetch_reached"] for r in rows),
        "ours_on_at_end": sum(r["ours_on_at_end"] for r in rows),
        "fetch_ever_sunk": sum(r["fetch_sunk_steps"] > 0 for r in rows),
        "fetch_first_sunk_minus_part_q": q(
            [r["fetch_first_sunk_minus_part"] for r in rows if r["fetch_first_sunk_minus_part"] is not None]
        ),  # fmt: skip
        "fetch_tipped": sum(r["fetch_tipped"] for r in rows),
        "fetch_outcome_tipped": {
            k: sum(r["fetch_outcome"] == k and r["fetch_tipped"] for r in rows)
            for k in ("long", "short", "wide", "off")
        },  # fmt: skip
        "rows": rows,
    }
    both = uo[:, -1] & ur[:, -1]
    out["both_final"] = {"episodes": int(both.sum()), "fetch_on_at_end": int((both & sr["on"][:, -1]).sum()),
                         "ours_on_at_end": int((both & so["on"][:, -1]).sum())}  # fmt: skip
    return out


def main(argv: list[str]) -> int:
    out = {}
    for arg in argv[1:]:
        name, path = arg.split("=", 1)
        out[name] = analyse(np.load(path))
    with open(argv[0], "w") as fh:
        json.dump(out, fh, indent=1)
    for name, v in out.items():
        print(name, json.dumps({k: x for k, x in v.items() if k != "ours_final_fetch_not"}))
        print("  ", json.dumps({k: x for k, x in v["ours_final_fetch_not"].items() if k != "rows"}))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
