"""Our Slide (MJX) alone on the probes ``slide_arm_c.py --arm reference`` gives for FetchSlide-v4, under some task
options: the light-press rim probe (``pads_rim_probe.py``'s, +x and the diagonal, the puck unturned), the hard press
(``slide_on_puck.py``'s, at 0, 0.01 and 0.02 m behind the centre) and the scripted strike
(``slide_press_probes.strike``), one step compile for the probes and one for the strike.

    PYTHONPATH=. python experiments/results/2026-11-28/slide-pads/analysis/slide_probes_mjx.py \
        --env-options finger=pads,finger_table=1 --strike 200 --out OUT.json

``--summarise FILE...``: one row per file, in ``slide_arm_c.py --summarise``'s columns: the rim's first slip +x /
diagonal with each offset's (1: slipped; one run each, since MJX's puck is an exact cylinder its turn changes
nothing), the light press's grip height above the puck's centre and drag per step (medians of the runs that held)
+x / diagonal, the hard press's grip height after the press and drag per step at 0 / 0.01 m, the strike's success
any / final and median landing past the goal.
"""

from __future__ import annotations

import argparse
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.join(HERE, *[".."] * 5)
for p in (HERE, ROOT, os.path.join(ROOT, "experiments", "reference"), os.path.join(ROOT, "experiments", "parity")):
    sys.path.insert(0, p)

OFFSETS = (0.0125, 0.015, 0.0175, 0.02, 0.0225, 0.025, 0.0275)
PRESS_OFFSETS = (0.0, 0.01, 0.02)


def run(options: str, strike: int, offsets=OFFSETS) -> dict:
    import jax
    import pads_rim_probe as rim
    import slide_on_puck
    import slide_press_probes as press

    import envs
    from splid_jax.common.values import parse_overrides

    opts = parse_overrides(options)
    env = envs.make("slide", **opts)
    step = jax.jit(env.step)
    import mujoco

    out = {"mujoco": mujoco.__version__, "env_options": options, "rim": [], "press": {}}
    for name in ("+x", "diag"):
        u = np.asarray(rim.DIRS[name])
        acts = rim.actions(u, -0.25, 0.5)
        for offset in offsets:
            row = {"dir": name, "offset": offset, **rim.measures(rim.ours(env, step, u, offset, acts), u)}
            out["rim"].append(row)
            print(row, flush=True)
    for offset in PRESS_OFFSETS:
        x = rim.ours(env, step, (1.0, 0.0), offset, slide_on_puck.ACTIONS)[:, :6]
        out["press"][str(offset)] = press.measures(x)
        print("press", offset, out["press"][str(offset)], flush=True)
    if strike:
        out["strike"] = press.strike(opts, strike)["ours"]
        print("strike", out["strike"], flush=True)
    return out


def summary(r: dict) -> str:
    cells = []
    for name in ("+x", "diag"):
        rows = [x for x in r["rim"] if x["dir"] == name]
        slipped = [x["offset"] for x in rows if x["slipped"]]
        marks = " ".join("1" if x["slipped"] else "0" for x in rows)
        cells.append(f"{min(slipped) if slipped else '>' + str(rows[-1]['offset'])} ({marks})")
    held = [x for x in r["rim"] if not x["slipped"]]

    def held_median(d: str, key: str) -> str:
        xs = [x[key] for x in held if x["dir"] == d]
        return f"{np.median(xs):.4f}" if xs else "-"

    light = " / ".join(f"{held_median(d, 'dragging')}, {held_median(d, 'drag_per_step')}" for d in ("+x", "diag"))
    hard = " / ".join(
        f"{r['press'][k]['grip_on_puck']:.4f}, {r['press'][k]['drag_per_step']:.4f}" for k in ("0.0", "0.01")
    )
    s = r.get("strike")
    strike = f"{s['success_any']} / {s['success_final']}; {s['along_q10_25_50_75_90'][2]:+.3f}" if s else "-"
    return f"| `{r['env_options']}` | {' / '.join(cells)} | {light} | {hard} | {strike} |"


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--env-options", default="finger=pads,finger_table=1")
    p.add_argument("--offsets", default=",".join(map(str, OFFSETS)), help="the rim probe's, m behind the centre")
    p.add_argument("--strike", type=int, default=0, metavar="N")
    p.add_argument("--out", default=None)
    p.add_argument("--summarise", nargs="+", metavar="JSON")
    args = p.parse_args(argv)
    import pads_rim_probe as rim

    if args.summarise:
        for f in args.summarise:
            print(summary(rim.read_json(f)))
        return 0
    result = run(args.env_options, args.strike, [float(v) for v in args.offsets.split(",")])
    if args.out:
        rim.write_json(args.out, result, indent=1)
    print(summary(result))
    return 0


if __name__ == "__main__":
    sys.exit(main())
