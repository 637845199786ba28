"""Success, BC loss and BC samples per newly stored pair of a Figure 3 directory's imitation learners,
against exploration episodes: the signature of their fall past the peak (NOTES, "The imitation learners'
fall past their peak on Push").

    python experiments/fall_signature.py experiments/results/2026-11-27/fig3-push-100k --out FILE.png
"""

from __future__ import annotations

import argparse
import json
import os

import numpy as np
from matplotlib.figure import Figure

METHODS = {"splid": "SPLID", "no-select": "SPLID without SELECT", "gcsl": "GCSL"}


def member_rows(figure_dir: str, method: str) -> tuple[dict, list[list[dict]]]:
    """The method's first member's config and every member's metrics."""
    with open(os.path.join(figure_dir, "figure.json")) as fh:
        members = json.load(fh)["runs"][method]["members"]
    rows = []
    for member in members:
        with open(os.path.join(figure_dir, method, member["run_dir"], "metrics.jsonl")) as fh:
            rows.append([json.loads(line) for line in fh])
    return members[0], rows


def mean_over_seeds(rows: list[list[dict]], key: str) -> tuple[np.ndarray, np.ndarray]:
    n = min(len(r) for r in rows)
    episodes = np.array([rows[0][i]["episodes"] for i in range(n)])
    return episodes, np.mean([[r[i][key] for i in range(n)] for r in rows], axis=0)


def samples_per_pair(rows: list[list[dict]], bc_samples: int) -> tuple[np.ndarray, np.ndarray]:
    """BC samples drawn per iteration over the pairs stored per iteration (metrics sum 5 iterations)."""
    episodes, stored = mean_over_seeds(rows, "select_accepted")
    every = rows[0][0]["iteration"]
    return episodes, bc_samples / np.maximum(stored / every, 1)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("figure_dir")
    parser.add_argument("--out", required=True, metavar="FILE.png")
    ns = parser.parse_args()
    fig = Figure(figsize=(14, 4.2))
    axes = fig.subplots(1, 3)
    for method, label in METHODS.items():
        config, rows = member_rows(ns.figure_dir, method)
        line = None
        for key, style in (("eval_success", "-"), ("eval_success_final", ":")):
            episodes, value = mean_over_seeds(rows, key)
            colour = None if line is None else line.get_color()
            (drawn,) = axes[0].plot(episodes, value, style, color=colour, label=f"{label}, {key[5:].replace('_', ' ')}")
            line = line or drawn
        axes[1].plot(*mean_over_seeds(rows, "bc_loss"), color=line.get_color(), label=label)
        samples = config["bc_steps"] * config["batch_size"]
        axes[2].plot(*samples_per_pair(rows, samples), color=line.get_color(), label=label)
    axes[0].set(ylabel="evaluation success (solid: any step, dotted: final step)", ylim=(0, 1))
    axes[1].set(ylabel="BC loss at the chunk's last iteration", yscale="log")
    axes[2].set(ylabel="BC samples per newly stored pair", yscale="log")
    for ax in axes:
        ax.set_xlabel("exploration episodes")
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=7)
    axes[2].legend(fontsize=8)
    fig.suptitle(f"{os.path.basename(os.path.normpath(ns.figure_dir))}: mean of 5 seeds", fontsize=10)
    fig.tight_layout()
    fig.savefig(ns.out, dpi=100)
    print(ns.out)


if __name__ == "__main__":
    main()
