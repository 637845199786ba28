"""Compare the scripted-controller results of our tasks with the reference's; write PARITY.md (and a PNG).

    python experiments/parity/compare.py --ours experiments/parity/results/ours.json \
        --reference experiments/parity/results/reference.json
"""

from __future__ import annotations

import argparse
import datetime
import json
import subprocess
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
TASK_ORDER = ("push", "slide", "pick_and_place", "reach")
FLAG_POINTS = 5.0  # a success difference above this many points is flagged
QUANTITIES = (
    ("object start x", lambda r: r["object_start"][0]),
    ("object start y", lambda r: r["object_start"][1]),
    ("object start z", lambda r: r["object_start"][2]),
    ("goal x", lambda r: r["goal"][0]),
    ("goal y", lambda r: r["goal"][1]),
    ("goal z", lambda r: r["goal"][2]),
    ("displacement x", lambda r: r["displacement"][0]),
    ("displacement y", lambda r: r["displacement"][1]),
    ("displacement z", lambda r: r["displacement"][2]),
    ("|displacement| xy", lambda r: float(np.hypot(*r["displacement"][:2]))),
    ("final distance to goal", lambda r: r["final_distance"]),
)


def rate(recs, key):
    return 100.0 * float(np.mean([r[key] for r in recs]))


def binomial_se(p_percent, n):
    p = p_percent / 100.0
    return 100.0 * float(np.sqrt(max(p * (1 - p), 1e-12) / n))


def summary(values):
    v = np.asarray(values, float)
    return f"{v.mean():.3f} ± {v.std():.3f} [{v.min():.3f}, {v.max():.3f}]"


def success_table(ours, ref, tasks):
    lines = [
        "| task | episodes (ours / ref) | any-step ours | any-step ref | diff (pts) | final-step ours | "
        "final-step ref | diff (pts) | flag |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for t in tasks:
        o, r = ours["tasks"][t]["episodes"], ref["tasks"][t]["episodes"]
        ao, ar = rate(o, "success_any"), rate(r, "success_any")
        fo, fr = rate(o, "success_final"), rate(r, "success_final")
        over = [name for name, diff in (("any step", ao - ar), ("final step", fo - fr)) if abs(diff) > FLAG_POINTS]
        flag = f"**{' and '.join(over)} > 5 pts**" if over else ""
        lines.append(
            f"| {t} | {len(o)} / {len(r)} | {ao:.1f} | {ar:.1f} | {ao - ar:+.1f} | {fo:.1f} | {fr:.1f} | "
            f"{fo - fr:+.1f} | {flag} |"
        )
    return lines


def distribution_table(ours, ref, task):
    o, r = ours["tasks"][task]["episodes"], ref["tasks"][task]["episodes"]
    lines = [f"### {task}", "", "| quantity | ours: mean ± std [min, max] | reference: mean ± std [min, max] |",
             "|---|---|---|"]
    for name, fn in QUANTITIES:
        if task == "reach" and name.startswith("object start"):
            name = name.replace("object", "gripper")
        lines.append(f"| {name} | {summary([fn(x) for x in o])} | {summary([fn(x) for x in r])} |")
    return lines


def plot(ours, ref, tasks, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cols = (("object start x", 0), ("object start y", 1), ("goal x", 3), ("goal y", 4), ("goal z", 5),
            ("|displacement| xy", 9), ("final distance to goal", 10))
    fig, axes = plt.subplots(len(tasks), len(cols), figsize=(3 * len(cols), 2.4 * len(tasks)), squeeze=False)
    for i, t in enumerate(tasks):
        for j, (name, q) in enumerate(cols):
            fn = QUANTITIES[q][1]
            a = [fn(x) for x in ours["tasks"][t]["episodes"]]
            b = [fn(x) for x in ref["tasks"][t]["episodes"]]
            lo, hi = min(min(a), min(b)), max(max(a), max(b))
            if hi - lo < 0.01:  # (nearly) constant: widen, so sub-millimetre float noise shows as one bar
                lo, hi = (lo + hi) / 2 - 0.01, (lo + hi) / 2 + 0.01
            bins = np.linspace(lo, hi + 1e-9, 25)
            ax = axes[i, j]
            ax.hist(b, bins=bins, alpha=0.5, label="reference")
            ax.hist(a, bins=bins, alpha=0.5, label="ours")
            ax.set_title(f"{t}: {name}", fontsize=8)
            ax.tick_params(labelsize=6)
    axes[0, 0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=80)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--ours", default=str(HERE / "results" / "ours.json"))
    p.add_argument("--reference", default=str(HERE / "results" / "reference.json"))
    p.add_argument("--out", default=str(HERE / "PARITY.md"))
    p.add_argument("--png", default=str(HERE / "parity.png"), help="'' skips the plot")
    p.add_argument("--bench", nargs="*", default=[], help="more run_reference.py JSONs whose throughput to list")
    p.add_argument("--also", nargs="*", default=[], metavar="LABEL=OURS_JSON",
                   help="more runs of ours (other devices or settings) for the success table")
    args = p.parse_args(argv)
    ours = json.loads(Path(args.ours).read_text())
    ref = json.loads(Path(args.reference).read_text())
    tasks = [t for t in TASK_ORDER if t in ours["tasks"] and t in ref["tasks"]]
    if not tasks:
        print("no task in both result files", file=sys.stderr)
        return 1
    try:
        commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True,
                                text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        commit = "unknown"

    lines = [
        "# Parity: scripted controllers in our MJX tasks vs Gymnasium-Robotics Fetch*-v4",
        "",
        f"Written {datetime.datetime.now(datetime.UTC).strftime('%Y-%m-%d')} by `python "
        f"experiments/parity/compare.py` at commit {commit}.",
        "",
        "| side | command | device | date | versions |",
        "|---|---|---|---|---|",
    ]
    for side in (ours, ref):
        versions = ", ".join(f"{k} {v}" for k, v in side.get("versions", {}).items())
        lines.append(f"| {side['side']} | `{side['command']}` | {side['device']} | {side['date']} | {versions} |")
    lines += [
        "",
        "## Success (%)",
        "",
        "Controllers: `envs/fetch/scripted.py`, the same functions on both sides. Success = achieved goal within "
        "0.05 m of the goal; any-step is the SPLID paper's convention, final-step HER's. Binomial standard "
        "error at 200 episodes and p = 0.5 is 3.5 points.",
        "",
        *success_table(ours, ref, tasks),
        "",
    ]
    benches = [ref] + [json.loads(Path(b).read_text()) for b in args.bench]
    benches = [b for b in benches if b.get("throughput")]
    if benches:
        lines += [
            "## Reference throughput (MuJoCo C, random actions)",
            "",
            "| machine | env | 1 process (steps/s) | N processes | N processes (steps/s) | speedup | load avg |",
            "|---|---|---|---|---|---|---|",
        ]
        for b in benches:
            thr = b["throughput"]
            load = b.get("load_average_at_start")
            load = f"{load[0]:.1f}" if load else "n/a"
            lines.append(
                f"| {b['device']} | {thr['env']} | {thr['single_process_steps_per_s']:.0f} | {thr['procs']} | "
                f"{thr['multi_process_steps_per_s']:.0f} | {thr['speedup']:.2f}x | {load} |"
            )
        lines += [
            "",
            "N-process rate = sum of each worker's own rate (pool start-up excluded); "
            f"{thr['steps_per_proc']} steps per process. Command: `{benches[-1]['command']}`.",
            "",
        ]
    if args.also:
        lines += ["## Other runs of ours (success %, any-step / final-step)", "",
                  "| run | device | overrides | " + " | ".join(tasks) + " |",
                  "|---|---|---|" + "---|" * len(tasks)]
        for item in args.also:
            label, _, path = item.rpartition("=")
            run = json.loads(Path(path).read_text())
            cells = []
            for t in tasks:
                if t in run["tasks"]:
                    recs = run["tasks"][t]["episodes"]
                    bad = sum(r.get("invalid", False) for r in recs)
                    cells.append(f"{rate(recs, 'success_any'):.1f} / {rate(recs, 'success_final'):.1f}"
                                 + (f" ({bad} NaN)" if bad else "") + f" n={len(recs)}")
                else:
                    cells.append("-")
            lines.append(f"| {label} | {run['device']} | {run.get('overrides') or '-'} | " + " | ".join(cells) + " |")
        lines.append("")
    timing = [
        f"| {t} | {ours['tasks'][t].get('compile_seconds', float('nan')):.0f} | {ours['tasks'][t]['seconds']:.1f} | "
        f"{ours['tasks'][t].get('env_steps_per_s', float('nan')):.0f} | {ref['tasks'][t]['seconds']:.1f} |"
        for t in tasks
    ]
    lines += [
        "## Run times of these scripted runs",
        "",
        "| task | ours: compile (s) | ours: run (s) | ours: env-steps/s | reference: run (s) |",
        "|---|---|---|---|---|",
        *timing,
        "",
        "## Distributions (mean ± std [min, max], metres)",
        "",
        "Object start and goal are sampled at reset; displacement = final - initial achieved goal.",
        "",
    ]
    for t in tasks:
        lines += distribution_table(ours, ref, t) + [""]
    if args.png:
        plot(ours, ref, tasks, args.png)
        lines += [f"![distributions]({Path(args.png).name})", ""]
    Path(args.out).write_text("\n".join(lines))
    print("wrote", args.out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
