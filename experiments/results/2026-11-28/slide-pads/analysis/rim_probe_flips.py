"""Per light-press probe JSON (``pads_rim_probe_polygon.py --yaws ...``): per side and direction the slips per offset
over the turns, the first slip, how many slips flipped the puck over (tilt > 90 degrees) and the largest tilt of the
runs that held and of all.

    python rim_probe_flips.py rim_probe_light_press_polygon_yaws.json.gz ...
"""

from __future__ import annotations

import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from pads_rim_probe import read_json  # noqa: E402


def flips(path: str) -> dict:
    rows = read_json(path)["rows"]
    out = {}
    for side in ("ours", "fetch"):
        for d in sorted({r["dir"] for r in rows}):
            rr = [r for r in rows if r["dir"] == d]
            offs = sorted({r["offset"] for r in rr})
            slips = [sum(r[side]["slipped"] for r in rr if r["offset"] == o) for o in offs]
            tilt = [r[side]["puck_tilt_deg_max_pressed"] for r in rr]
            held = [r[side]["puck_tilt_deg_max_pressed"] for r in rr if not r[side]["slipped"]]
            first = min((o for o, n in zip(offs, slips, strict=True) if n), default=None)
            out[f"{side} {d}"] = {"slips_per_offset": slips, "first_slip": first, "slips": sum(slips),
                                  "flipped": sum(t > 90 for t in tilt), "tilt_max": max(tilt),
                                  "tilt_max_held": max(held, default=None)}  # fmt: skip
    return out


if __name__ == "__main__":
    for p in sys.argv[1:]:
        print(p)
        for k, v in flips(p).items():
            print(" ", k, json.dumps(v))
