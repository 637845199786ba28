"""Our HER runs beside spitis/mrl's published DDPG+HER curves, on the same axes.

mrl's points are read off its benchmark plots (``experiments/benchmarks/plots/robotics_fetch_*.png``: 3 seeds,
8 envs, success at the final step, 50 steps per episode). Each of our runs is a sweep directory (one member per
seed); the figure shows the mean and standard error over its members, at the final step (solid) and at any
step (dotted), against environment steps (bottom) and episodes (top).

    python experiments/her_vs_mrl.py --run push=RUN_A --run pick_and_place=RUN_B --run slide=RUN_C \
        --baselines push=RUN_D --out DIR
"""

from __future__ import annotations

import argparse
import csv
import glob
import json
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from splid_jax.common.images import save_figure  # noqa: E402

STEPS_PER_EPISODE = 50
# (environment steps, final-step success) read off mrl's plots; "FA" is its futureactual_2_2 relabelling
_PUSH_FA = [(0.25e6, 0.85), (0.28e6, 0.95), (0.5e6, 0.99)]
_PICK = [(0.35e6, 0.5), (0.65e6, 0.95), (1e6, 0.97)]  # HER+FA: about the same
MRL = {
    "push": {"HER": [(0.25e6, 0.85), (0.5e6, 0.93), (1e6, 0.97)], "HER+FA": _PUSH_FA},
    "pick_and_place": {"HER": _PICK, "HER+FA": _PICK},
    "slide": {"HER": [(0.9e6, 0.6), (2.5e6, 0.8)], "HER+FA": [(0.3e6, 0.6), (0.75e6, 0.8), (1.8e6, 0.87)]},
}
TITLES = {"push": "Push", "pick_and_place": "PickAndPlace", "slide": "Slide"}


def curves(sweep_dir: str) -> dict[str, np.ndarray]:
    """Per evaluation (up to the shortest member): env steps, episodes, and the mean and s.e. of both measures."""
    members = [[json.loads(line) for line in open(p)] for p in sorted(glob.glob(f"{sweep_dir}/*/metrics.jsonl"))]
    if not members:
        raise SystemExit(f"no member metrics under {sweep_dir}")
    n = min(len(m) for m in members)
    table = {k: np.array([[r[k] for r in m[:n]] for m in members]) for k in ("eval_success", "eval_success_final")}
    out = {"env_steps": np.array([r["env_steps"] for r in members[0][:n]]), "seeds": len(members)}
    out["episodes"] = np.array([r["episodes"] for r in members[0][:n]])
    for k, v in table.items():
        out[k] = v.mean(0)
        out[k + "_se"] = v.std(0, ddof=1) / np.sqrt(len(members)) if len(members) > 1 else 0 * v[0]
    return out


def pairs(items: list[str]) -> dict[str, str]:
    out = {}
    for item in items:
        task, sep, path = item.partition("=")
        if not sep or task not in MRL:
            raise SystemExit(f"invalid {item!r}: must be TASK=RUN_DIR with TASK one of {', '.join(MRL)}")
        out[task] = path
    return out


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--run", action="append", default=[], help="TASK=SWEEP_DIR of our HER (mrl's settings)")
    p.add_argument("--baselines", action="append", default=[], help="TASK=SWEEP_DIR of our HER (Baselines' settings)")
    p.add_argument("--label", default="ours, mrl settings", help="legend label of the --run curves")
    p.add_argument("--out", required=True)
    args = p.parse_args()
    ours, base = pairs(args.run), pairs(args.baselines)
    tasks = [t for t in MRL if t in ours or t in base]
    os.makedirs(args.out, exist_ok=True)
    fig, axes = plt.subplots(1, len(tasks), figsize=(5.2 * len(tasks), 4.2), squeeze=False)
    rows = []
    for ax, task in zip(axes[0], tasks, strict=True):
        for label, runs, colour in ((args.label, ours, "C0"), ("ours, Baselines settings", base, "C2")):
            if task not in runs:
                continue
            c = curves(runs[task])
            x = c["env_steps"] / 1e6
            ax.plot(x, c["eval_success_final"], color=colour, label=f"{label} (final step, {c['seeds']} seeds)")
            lo, hi = (
                c["eval_success_final"] - c["eval_success_final_se"],
                c["eval_success_final"] + c["eval_success_final_se"],
            )
            ax.fill_between(x, lo, hi, color=colour, alpha=0.2)
            ax.plot(x, c["eval_success"], color=colour, linestyle=":", label=f"{label} (any step)")
            for i in range(len(x)):
                rows.append([task, label, int(c["episodes"][i]), int(c["env_steps"][i]),
                             f"{c['eval_success'][i]:.4f}", f"{c['eval_success_final'][i]:.4f}"])  # fmt: skip
        for (name, points), marker in zip(MRL[task].items(), ("o", "s"), strict=True):
            xs, ys = zip(*points, strict=True)
            ax.scatter(
                np.array(xs) / 1e6, ys, marker=marker, color="k", zorder=3, label=f"mrl {name} (read off, final)"
            )
        ax.set_xlabel("environment steps (millions)")
        ax.set_ylabel("success rate")
        ax.set_ylim(0, 1.02)
        ax.set_title(TITLES[task])
        ax.grid(alpha=0.3)
        top = ax.secondary_xaxis("top", functions=(lambda m: m * 1e6 / STEPS_PER_EPISODE / 1e3,
                                                   lambda k: k * 1e3 * STEPS_PER_EPISODE / 1e6))  # fmt: skip
        top.set_xlabel("episodes (thousands)")
        ax.legend(fontsize=7, loc="lower right")
    fig.tight_layout()
    save_figure(fig, os.path.join(args.out, "her_vs_mrl.png"), dpi=110)
    with open(os.path.join(args.out, "her_vs_mrl.csv"), "w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(["task", "run", "episodes", "env_steps", "success_any", "success_final"])
        writer.writerows(rows)
    print(os.path.join(args.out, "her_vs_mrl.png"))


if __name__ == "__main__":
    main()
