"""Whether a task's solver choices (``solver_loops``, or any task options: ``--variants``) keep its physics' path,
and what each costs a control step.

Runs the same random actions from the same starts under each variant (a jitted ``lax.scan`` of ``--steps``
batched steps), then reports each variant's compile time, its median ms per control step over ``--repeats``
timed calls after the first (``block_until_ready``), and its qpos difference from the first variant's after the
first, the tenth and the last step: the largest over the envs, and the median env's. Contacts amplify
float rounding, so a few envs part after some steps whichever variant is compared; the median env shows
whether the arithmetic is the same.

    python experiments/solver_paths.py --task push --batch 64 --steps 50 --choices gpu-search unrolled fused
    python experiments/solver_paths.py --task push --variants "" collision=mjx   # the task's default first
    python experiments/solver_paths.py --batch 4 --steps 5 --repeats 1    # CPU smoke test
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import statistics
import sys
import time
from pathlib import Path

import jax
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

with contextlib.redirect_stdout(io.StringIO()):  # MJX prints a warp notice on import
    import envs
from bench_env import parse_variant  # noqa: E402  this folder's scripts share their parsing


def run(task: str, options: dict, batch: int, steps: int, repeats: int) -> tuple[np.ndarray, dict]:
    env = envs.make(task, **options)
    state = jax.jit(lambda k: jax.vmap(env.reset)(jax.random.split(k, batch)))(jax.random.PRNGKey(0))
    actions = jax.random.uniform(jax.random.PRNGKey(1), (steps, batch, env.action_size), minval=-1, maxval=1)

    def step(s, a):
        s = jax.vmap(env.step)(s, a)
        return s, s.physics.qpos

    t0 = time.perf_counter()
    program = jax.jit(lambda s: jax.lax.scan(step, s, actions)[1]).lower(state).compile()
    compile_s = time.perf_counter() - t0
    path = np.asarray(program(state))
    runs = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        jax.block_until_ready(program(state))
        runs.append(time.perf_counter() - t0)
    return path, {"compile_s": round(compile_s, 2), "ms_per_step": round(1e3 * statistics.median(runs) / steps, 4)}


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--task", default="push")
    p.add_argument("--choices", nargs="+", default=["gpu-search", "fused"], help="solver_loops values, first the base")
    p.add_argument("--variants", nargs="+", type=parse_variant, default=None,
                   help="task options per variant as KEY=VALUE[,KEY=VALUE] ('' for the defaults), first the base; "
                        "replaces --choices")  # fmt: skip
    p.add_argument("--batch", type=int, default=64)
    p.add_argument("--steps", type=int, default=50)
    p.add_argument("--repeats", type=int, default=5)
    p.add_argument("--out", type=Path, default=None)
    a = p.parse_args()
    print(f"device {jax.devices()[0].device_kind}, jax {jax.__version__}, {a.task}, {a.batch} envs, {a.steps} steps")
    rows, base = [], None
    variants = a.variants if a.variants is not None else [parse_variant(f"solver_loops={c}") for c in a.choices]
    for label, options in variants:
        path, row = run(a.task, options, a.batch, a.steps, a.repeats)
        row = {"variant": label, **row}
        if base is None:
            base = path
        else:
            diff = np.abs(path - base).max(axis=2)  # [steps, envs]
            marks = sorted({0, min(9, a.steps - 1), a.steps - 1})
            row["max_qpos_diff"] = {m + 1: float(diff[m].max()) for m in marks}
            row["median_env_qpos_diff"] = {m + 1: float(np.median(diff[m])) for m in marks}
            row["speed_vs_base"] = round(rows[0]["ms_per_step"] / row["ms_per_step"], 3)
        rows.append(row)
        print(json.dumps(row), flush=True)
    if a.out:
        a.out.write_text(json.dumps({"device": jax.devices()[0].device_kind, "jax": jax.__version__, "task": a.task,
                                     "batch": a.batch, "steps": a.steps, "rows": rows}, indent=1))  # fmt: skip


if __name__ == "__main__":
    main()
