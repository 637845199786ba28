"""Pool `evaluate --reference` JSONs over seeds, each policy grouped by the strategy it learnt (parting.py's share of
steps with the grip resting on the puck: above 0.25 it rides the puck, else it strikes).

    python pool.py OUT.json PARTING.json|- sSEED.json ...
"""

from __future__ import annotations

import json
import sys

RIDES = 0.25
OURS = "ours"


def pool(rows: list[dict], fetch_key: str) -> dict:
    def mean(key: str, i: int) -> float:
        return round(sum(r[key][i] for r in rows) / len(rows), 3)

    ours, fetch = [mean(OURS, 0), mean(OURS, 1)], [mean(fetch_key, 0), mean(fetch_key, 1)]
    gap = [round(ours[0] - fetch[0], 3), round(ours[1] - fetch[1], 3)]
    return {"seeds": len(rows), OURS: ours, fetch_key: fetch, "gap": gap}


def main(out_path: str, parting_path: str, *files: str) -> None:
    parting = json.load(open(parting_path)) if parting_path != "-" else {}
    rows, groups = {}, {}
    for name in files:
        d = json.load(open(name))
        seed = d["run_dir"].rsplit("-s", 1)[1]
        fetch_key = "fetch_v4_mujoco" + d["versions"]["mujoco"].replace(".", "")[:3]
        row = {"iteration": d["step"], "env_options": d["env_options"], "episodes": d["ours"]["episodes"],
               OURS: [d["ours"]["success_any"], d["ours"]["success_final"]],
               fetch_key: [d["fetch"]["success_any"], d["fetch"]["success_final"]]}
        traced = parting.get("s" + seed)
        if traced:
            on = traced["ours"]["phase_share"]["on"]
            row["on_puck_step_share_ours_fetch"] = [on, traced["fetch"]["phase_share"]["on"]]
            row["fetch_on_steps_sunk_share"] = traced["fetch"]["on_steps_sunk_share"]
            row["group"] = "rides" if on > RIDES else "strikes"
            groups.setdefault(row["group"], []).append(row)
        rows[seed] = row
    result = {**rows, "pooled": pool(list(rows.values()), fetch_key)}
    result.update({f"pooled_{g}": pool(members, fetch_key) for g, members in groups.items()})
    with open(out_path, "w") as fh:
        json.dump(result, fh, indent=1)
    for key, row in result.items():
        print(key, json.dumps(row))


if __name__ == "__main__":
    main(*sys.argv[1:])
