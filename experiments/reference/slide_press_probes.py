"""``slide_on_puck.py``'s press at three offsets (0, 0.01 m behind the puck's centre and 0.02, on the rim) in our
Slide under some task options and in FetchSlide-v4, one compile for the three: the numbers that say whether a pressed
gripper rides the puck, how fast it drags it, and whether its fingers slip off at the rim.

    python experiments/reference/slide_press_probes.py --env-options finger=pads,finger_table=1 --out FILE.json

Per offset and simulator: ``grip_on_puck``, the grip's height above the puck's centre after the 6 steps pressed
down (steps 4 to 10), and ``grip_dragging``, its mean over the 8 steps driven forward while pressed (11 to 18);
``drag_per_step``, the puck's mean x advance per control step over those 8; ``puck_moved``, its x advance by the
probe's end; ``off``, whether the grip ended below the puck's top face plus the fingertips' reach (the fingers
beside the puck, not on it); ``puck_aside``, its y move by the end. ``--lateral``: the press also off the puck's
centre line (m to its side), where the reference's pressed puck leaves sideways and ours stays centred.

``--strike N``: the scripted strike (``envs.fetch.scripted.slide``) in our task on N episodes
(``experiments/parity/run_ours.py``), beside the reference's 200 recorded in
``experiments/parity/results/strike_reference.json``: success at any and at the final step, and where the puck
ends along the start-to-goal line (``along``, past the goal > 0) and off it (``across``).

``--libccd``: the reference collides its convex pairs (the pads and the puck) with libccd instead of MuJoCo's native
collider, its default; the two disagree on these contacts (``experiments/reference/results/slide-pads.md``).
"""

from __future__ import annotations

import argparse
import json
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(1, os.path.join(HERE, "..", ".."))
sys.path.insert(2, os.path.join(HERE, "..", "parity"))
REFERENCE_STRIKE = os.path.join(HERE, "..", "parity", "results", "strike_reference.json")

OFFSETS = (0.0, 0.01, 0.02)
PRESSED, DRAG = slice(10, 11), slice(11, 19)  # rows of the [T + 1, 6] traces: after the press, the pressed drive
ON_TOP = 0.015  # grip above the puck's centre (m) at or over which the fingers rest on its top face


def measures(x: np.ndarray) -> dict:
    """The probe's numbers from one trace [T + 1, 6] (grip xyz, puck xyz per control step)."""
    above = x[:, 2] - x[:, 5]
    puck = x[:, 3] - x[0, 3]
    return {
        "grip_on_puck": round(float(above[PRESSED].mean()), 4),
        "grip_dragging": round(float(above[DRAG].mean()), 4),
        "drag_per_step": round(float(np.diff(puck[10:19]).mean()), 4),
        "puck_moved": round(float(puck[-1]), 4),
        "off": bool(above[-1] < ON_TOP),
        "puck_aside": round(float(x[-1, 4] - x[0, 4]), 4),
    }


def strike_stats(episodes: list[dict]) -> dict:
    """Success shares and the landing's quantiles from records with success_any, success_final, along, across."""
    along = np.array([e["along"] for e in episodes])
    across = np.array([e["across"] for e in episodes])
    q = lambda x: [round(float(v), 4) for v in np.quantile(x, (0.1, 0.25, 0.5, 0.75, 0.9))]  # noqa: E731
    return {
        "episodes": len(episodes),
        "success_any": round(float(np.mean([e["success_any"] for e in episodes])), 3),
        "success_final": round(float(np.mean([e["success_final"] for e in episodes])), 3),
        "along_q10_25_50_75_90": q(along),
        "across_q10_25_50_75_90": q(across),
    }


def strike(options: dict, episodes: int, libccd: bool = False) -> dict:
    """The scripted strike in our task and the reference's recorded one, as ``strike_stats``."""
    import run_ours

    records = run_ours.run_task("slide", episodes, 0, options)["episodes"]
    ours = []
    for r in records:
        start, goal, disp = (np.asarray(r[k][:2]) for k in ("object_start", "goal", "displacement"))
        d = goal - start
        n = float(np.linalg.norm(d))
        ours.append({**r, "along": float(disp @ d / n - n), "across": float(abs(disp[0] * d[1] - disp[1] * d[0]) / n)})
    if libccd:  # the reference's strike run here, under the other collider
        import run_reference
        import slide_strike

        make_env = run_reference.make_env
        run_reference.make_env = lambda name: _with_libccd(make_env(name))
        try:
            reference = slide_strike.run_reference(200, 0)["episodes"]
        finally:
            run_reference.make_env = make_env
    else:
        with open(REFERENCE_STRIKE) as fh:
            reference = json.load(fh)["episodes"]
    return {"ours": strike_stats(ours), "fetch": strike_stats(reference)}


def _with_libccd(env):
    """``env`` (a FetchSlide-v4) colliding convex pairs with libccd rather than MuJoCo's native collider."""
    import mujoco

    env.unwrapped.model.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_NATIVECCD)
    return env


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--env-options", default="", help="our task's fields, e.g. finger=pads,finger_table=1")
    p.add_argument("--no-reference", action="store_true", help="ours only")
    p.add_argument("--offsets", default=",".join(map(str, OFFSETS)), help="comma-separated, m behind the centre")
    p.add_argument("--lateral", default="0", help="comma-separated, m to the side of the puck's centre line")
    p.add_argument("--strike", type=int, default=0, metavar="N", help="also the scripted strike on N episodes")
    p.add_argument("--no-press", action="store_true", help="the strike only")
    p.add_argument("--libccd", action="store_true",
                   help="the reference under libccd, not MuJoCo's native convex collider (its strike then run here)")
    p.add_argument("--out", default=None)
    args = p.parse_args(argv)
    import slide_on_puck as probe

    import envs
    from splid_jax.common.values import parse_overrides
    from splid_jax.reference.extra import import_reference

    options = parse_overrides(args.env_options)
    env = envs.make("slide", **options)
    if not args.no_reference:
        import_reference()
        if args.libccd:
            make_reference = probe.make_reference
            probe.make_reference = lambda task: _with_libccd(make_reference(task))
    result = {"env_options": args.env_options, "reference_collider": "libccd" if args.libccd else "native",
              "offsets": {}}
    presses = [(float(x), float(y)) for x in args.offsets.split(",") for y in args.lateral.split(",")]
    for offset, lateral in () if args.no_press else presses:
        puck = probe.pressed_puck(offset, lateral)
        row = {"ours": measures(probe.ours(env, puck, probe.ACTIONS))}
        if not args.no_reference:
            row["fetch"] = measures(probe.reference(env, puck, probe.ACTIONS))
        result["offsets"][str(offset) if lateral == 0 else f"{offset}, {lateral} aside"] = row
        for name, m in row.items():
            values = " ".join(f"{k}={v}" for k, v in m.items())
            print(f"offset {offset:.4f} aside {lateral:.4f} {name:5s} {values}", flush=True)
    if args.strike:
        result["strike"] = strike(options, args.strike, args.libccd)
        for name, m in result["strike"].items():
            print(f"strike {name:5s} " + " ".join(f"{k}={v}" for k, v in m.items()), flush=True)
    if args.out:
        with open(args.out, "w") as fh:
            json.dump(result, fh, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
