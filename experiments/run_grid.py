"""Several ``splid_jax.train`` runs at once on one device, then a table of what each reached.

    python experiments/run_grid.py --out runs/grid --common "--env push --iterations 80 --num-envs 64" \
        --run base= --run buf100k="--buffer-size 100000" --run bc1000="--bc-steps 1000"

Runs go one after another unless ``--parallel K``: on one H100 (2026-11-23) six concurrent Push
runs at 64 envs took 11.5 s per iteration each against 1.2 s alone, so sharing the device loses
time; concurrent wall-clock figures are no speed measurement. Each run writes
``OUT/NAME/metrics.jsonl``; ``--summary-only`` just prints the table of existing run dirs."""

from __future__ import annotations

import argparse
import os
import shlex
import subprocess
import sys
import time

import numpy as np

from splid_jax import plot


def _first(col: dict, level: float, key: str) -> str:
    """``key`` at the first evaluation with success >= ``level``, or "-"."""
    hit = np.flatnonzero(col["eval_success"] >= level)
    return f"{col[key][hit[0]]:.0f}" if hit.size else "-"


def summary(run_dirs: list[str]) -> str:
    rows = [
        "| run | episodes to 0.8 | episodes to 0.9 | wall s to 0.9 | best (episodes) | last (final step) | episodes |",
        "|---|---:|---:|---:|---|---|---:|",
    ]
    for d in run_dirs:
        try:
            col = plot.load_run(d).columns  # tolerates a last line cut off by a stopped run
        except plot.PlotError:
            rows.append(f"| {os.path.basename(d)} | - | - | - | - | - | 0 |")
            continue
        best = int(np.argmax(col["eval_success"]))
        rows.append(
            f"| {os.path.basename(d)} | {_first(col, 0.8, 'episodes')} | {_first(col, 0.9, 'episodes')} | "
            f"{_first(col, 0.9, 'wall_s')} | {col['eval_success'][best]:.3f} ({col['episodes'][best]:.0f}) | "
            f"{col['eval_success'][-1]:.3f} ({col['eval_success_final'][-1]:.3f}) | {col['episodes'][-1]:.0f} |"
        )
    return "\n".join(rows)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", required=True, help="parent directory of the run dirs")
    p.add_argument("--common", default="", help="flags every run gets")
    p.add_argument("--run", action="append", default=[], metavar="NAME=FLAGS", help="one run: its name and flags")
    p.add_argument("--summary-only", action="store_true", help="print the table of the run dirs under --out")
    p.add_argument("--parallel", type=int, default=1, help="runs at once on the device (default 1)")
    args = p.parse_args(argv)
    if args.summary_only:
        names = sorted(n for n in os.listdir(args.out) if os.path.isdir(os.path.join(args.out, n)))
        print(summary([os.path.join(args.out, n) for n in names]))
        return 0
    os.makedirs(args.out, exist_ok=True)
    env = dict(os.environ, XLA_PYTHON_CLIENT_PREALLOCATE="false")
    procs, dirs = [], []

    def wait(name, proc, t0):
        rc = proc.wait()
        print(f"{name}: exit {rc} after {time.time() - t0:.0f} s", flush=True)

    for spec in args.run:
        if len(procs) >= max(1, args.parallel):
            wait(*procs.pop(0))
        name, _, flags = spec.partition("=")
        run_dir = os.path.join(args.out, name)
        cmd = [sys.executable, "-m", "splid_jax.train", *shlex.split(args.common), *shlex.split(flags)]
        cmd += ["--run-dir", run_dir, "--checkpoint-every", "0", "--quiet"]
        log = open(os.path.join(args.out, f"{name}.log"), "w")
        log.write(" ".join(cmd) + "\n")
        log.flush()
        procs.append((name, subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT, env=env), time.time()))
        dirs.append(run_dir)
    for run in procs:
        wait(*run)
    print(summary(dirs))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
