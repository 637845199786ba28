"""Slip offsets, the puck's creep ahead of the grip and its tilt over the landing and press, from the light-press rim
probes' JSON (ours on the plane and on the box table in MJX, FetchSlide-v4, ours on the box table in MuJoCo C).

    python rim_probe_summary.py   # in this folder; writes rim_probe_box_table_summary.json
"""

import json

SETS = {
    "ours_plane_mjx": ("rim_probe_light_press.json", "ours"),
    "fetch_slide_v4": ("rim_probe_light_press.json", "fetch"),
    "ours_box_table_mjx": ("rim_probe_light_press_box_table.json", "ours"),
    "ours_box_table_mujoco_c": ("rim_probe_light_press_c_box_table.json", "c_ours_model"),
}
ABOUT = ("light-press rim probe (pads_rim_probe.py): per direction, the commanded offsets that slipped; per run, the "
         "puck's centre ahead of the grip as the pads land (trace step 1) and at the press's end (step 6), its largest "
         "ahead and tilt (deg) over the landing and press (trace steps 1 to 7)")  # fmt: skip


def run(r: dict) -> dict:
    t = r["trace"]
    return {"ahead_landing": t["puck_ahead"][1], "ahead_press_end": t["puck_ahead"][6],
            "ahead_max": max(t["puck_ahead"][1:8]), "tilt_max": max(t["puck_tilt_deg"][1:8])}  # fmt: skip


def main() -> None:
    out = {"about": ABOUT, "sets": {}}
    for name, (f, key) in SETS.items():
        with open(f) as fh:
            rows = json.load(fh)["rows"]
        s = {}
        for d in ("+x", "diag"):
            rr = [r for r in rows if r["dir"] == d]
            s[d] = {"slipped": [r["offset"] for r in rr if r[key]["slipped"]],
                    "runs": {str(r["offset"]): run(r[key]) for r in rr}}  # fmt: skip
            print(name, d, "slipped", s[d]["slipped"], s[d]["runs"]["0.0175"])
        out["sets"][name] = s
    with open("rim_probe_box_table_summary.json", "w") as fh:
        json.dump(out, fh, indent=1)


if __name__ == "__main__":
    main()
