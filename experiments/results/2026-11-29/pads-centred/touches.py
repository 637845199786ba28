"""Per seed, the episodes one simulator ends on the goal and the other does not, from `evaluate --traces` files:
the reference's outcome where only ours succeeds, and how each simulator's pads last left the puck (its speed then,
the distance it slid after, the step) and how often they touched it (touch segments per episode).

    PYTHONPATH=. python experiments/results/2026-11-29/pads-centred/touches.py s9200=T.npz ...
"""

from __future__ import annotations

import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "2026-11-28", "slide-pads-contact", "traces"))
import parting  # noqa: E402


def median_last(touches: list[dict], idx: np.ndarray) -> str:
    pick = lambda k: np.array([touches[i][k] for i in idx], float)  # noqa: E731
    speed, slid, step = np.nanmedian(pick("speed")), np.nanmedian(pick("slid")), np.median(pick("step"))
    return f"{speed:.3f} m/s, slid {slid:.3f} m, step {step:.0f}"


def segments(s: dict) -> np.ndarray:
    t = s["touch"].astype(int)
    return (np.diff(t, axis=1) == 1).sum(1) + t[:, 0]


def main(argv: list[str]) -> None:
    for arg in argv:
        name, path = arg.split("=", 1)
        z = np.load(path)
        so, sr = parting.per_step(z["ours_obs"], z["goal_ours"]), parting.per_step(z["fetch_obs"], z["goal_fetch"])
        uo, ur = z["ours_success"], z["fetch_success"]
        lo = [parting.last_touch(so, i) for i in range(len(uo))]
        lr = [parting.last_touch(sr, i) for i in range(len(uo))]
        ours, fetch = uo[:, -1].astype(bool), ur[:, -1].astype(bool)
        only_ours, both = np.flatnonzero(ours & ~fetch), np.flatnonzero(ours & fetch)
        outcomes: dict[str, int] = {}
        for i in only_ours:
            key = parting.outcome(sr, ur, i)
            outcomes[key] = outcomes.get(key, 0) + 1
        print(f"{name}: final ours {ours.sum()}, reference {fetch.sum()}; only ours {len(only_ours)}, only the "
              f"reference {int((~ours & fetch).sum())}; the reference's outcome where only ours succeeds {outcomes}")
        print(f"   only ours, last touch: ours {median_last(lo, only_ours)}; reference {median_last(lr, only_ours)}")
        print(f"   both, last touch:      ours {median_last(lo, both)}; reference {median_last(lr, both)}")
        n_ours, n_fetch = segments(so).mean(), segments(sr).mean()
        print(f"   touch segments per episode, mean: ours {n_ours:.2f}, reference {n_fetch:.2f}")


if __name__ == "__main__":
    main(sys.argv[1:])
