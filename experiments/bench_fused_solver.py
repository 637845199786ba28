"""The constraint solve alone: MJX's (as the task runs it by default) against ``envs/fused_solver.py``'s, on
the pre-solve states of a task's envs after some scripted steps (contacts made), per batch size.

Each program runs ``--chain`` solves in a row inside one jitted loop, each warm started from the last one's
accelerations, so a call's time over ``--chain`` is one solve's latency as a step pays it, not the launch of
one call. Compile time apart; median of ``--repeats`` timed calls after a warm-up (``block_until_ready``).
Reports each solver's ms per solve and its largest difference in qacc from MJX's (one solve, same states).
On a GPU the fused solve runs as its Pallas kernel (``--warps``: warps per env; Triton's default is 4), on a
CPU as XLA code.

    python experiments/bench_fused_solver.py --task push --batch 16 125 1024 --warps 1 2 4 --out fused.json
    python experiments/bench_fused_solver.py --task push --batch 4 --chain 2 --repeats 2   # CPU smoke test
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
    from mujoco import mjx
    from mujoco.mjx._src import forward as mjx_forward
    from mujoco.mjx._src import solver as mjx_solver

import envs  # noqa: E402
from envs import fused_solver  # noqa: E402
from envs.base import data_with  # noqa: E402
from envs.fetch.kernels import KERNELS, mjx_with_kernels  # noqa: E402
from envs.fetch.scripted import CONTROLLERS  # noqa: E402
from envs.mjx_patch import patched_mjx  # noqa: E402


def presolve_states(env, batch: int, steps: int, seed: int):
    """MJX Data of ``batch`` envs after ``steps`` scripted steps, forward dynamics run up to the solve."""
    state = jax.jit(jax.vmap(env.reset))(jax.random.split(jax.random.PRNGKey(seed), batch))
    act, step = jax.jit(jax.vmap(CONTROLLERS[env.kind])), jax.jit(jax.vmap(env.step))
    for _ in range(steps):
        state = step(state, act(state.obs, state.desired_goal))
    model, phys = env.mjx_model, state.physics

    def before_solve(p):
        data = data_with(mjx.make_data(model), p)
        with patched_mjx(solve=lambda m, d: d):  # MJX's forward dynamics with its solve left out
            return mjx_forward.forward(model, data)

    return jax.jit(jax.vmap(before_solve))(phys)


def chained(solve_one, chain: int):
    """``chain`` solves in a row, each warm started from the last one's qacc."""

    def run(d):
        def body(_, warm):
            return jax.vmap(solve_one)(d.replace(qacc_warmstart=warm)).qacc

        return jax.lax.fori_loop(0, chain, body, d.qacc_warmstart)

    return jax.jit(run)


def timed(program, d, repeats: int) -> tuple[float, float]:
    t0 = time.perf_counter()
    compiled = program.lower(d).compile()
    compile_s = time.perf_counter() - t0
    jax.block_until_ready(compiled(d))
    runs = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        jax.block_until_ready(compiled(d))
        runs.append(time.perf_counter() - t0)
    return compile_s, statistics.median(runs)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--task", default="push")
    p.add_argument("--batch", nargs="+", type=int, default=[16, 125])
    p.add_argument("--warps", nargs="+", type=int, default=[4], help="warps per env of the kernel (GPU only)")
    p.add_argument("--steps", type=int, default=15, help="scripted steps before the solve (default 15)")
    p.add_argument("--chain", type=int, default=20, help="solves per timed call (default 20)")
    p.add_argument("--repeats", type=int, default=5)
    p.add_argument("--out", type=Path, default=None)
    a = p.parse_args()
    env = envs.make(a.task)
    if env.solver_loops in KERNELS:  # MJX's own solve as the task would run it without the kernel
        env = envs.make(a.task, solver_loops="gpu-search")
    model = env.mjx_model
    gpu = jax.default_backend() == "gpu"

    def mjx_solve(d):
        with mjx_with_kernels(env):
            return mjx_solver.solve(model, d)

    variants = {f"mjx ({env.solver_loops})": mjx_solve}
    if gpu:
        for w in a.warps:
            variants[f"fused kernel, {w} warps"] = lambda d, w=w: fused_solver.solve(model, d, True, num_warps=w)
    else:
        variants["fused (XLA)"] = lambda d: fused_solver.solve(model, d, False)
    rows = []
    print(f"device {jax.devices()[0].device_kind}, jax {jax.__version__}, task {a.task}, chain {a.chain}")
    for batch in a.batch:
        d = presolve_states(env, batch, a.steps, seed=batch)
        reference = np.asarray(jax.jit(jax.vmap(mjx_solve))(d).qacc)
        for name, solve_one in variants.items():
            row = {"task": a.task, "batch": batch, "solver": name}
            try:
                compile_s, run_s = timed(chained(solve_one, a.chain), d, a.repeats)
                qacc = np.asarray(jax.jit(jax.vmap(solve_one))(d).qacc)
                scale = max(float(np.abs(reference).max()), 1e-30)
                row |= {"compile_s": round(compile_s, 2), "ms_per_solve": round(1e3 * run_s / a.chain, 4),
                        "max_rel_qacc_diff": float(np.abs(qacc - reference).max() / scale)}  # fmt: skip
            except Exception as e:  # a kernel Triton cannot compile is a result, not the end of the sweep
                row["error"] = f"{type(e).__name__}: {str(e).splitlines()[0][:300] if str(e) else ''}"
            rows.append(row)
            print(json.dumps(row), flush=True)
    if a.out:
        a.out.write_text(json.dumps({"device": jax.devices()[0].device_kind, "jax": jax.__version__, "rows": rows,
                                     "chain": a.chain, "repeats": a.repeats}, indent=1))  # fmt: skip


if __name__ == "__main__":
    main()
