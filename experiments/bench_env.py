"""Throughput of the MJX tasks: a jitted ``lax.scan`` of N control steps of the batched step with
random actions, for each task, batch size and physics variant.

Compile time is reported apart; then the median of ``--repeats`` timed runs (``block_until_ready``)
gives control steps/s (batch x steps / s) and physics steps/s (x substeps). Memory: the compiled
program's argument/output/temporary bytes (XLA's memory analysis, any device) and the device's peak
bytes in use where the device reports it (GPUs). A batch that fails (e.g. out of memory) is recorded
with its error and the larger batches of that task and variant are skipped.

On a 2-core CPU (jax 0.10.2, batch 64, 20 steps) it measured, in control steps/s at the default
10 x 4 ms and at 20 x 2 ms: reach 59,500 / 26,600, push 1,720 / 760, slide 960 / 540,
pick_and_place 880 / 500; compile 6 s (reach) to 28 s (pick_and_place).

Examples::

    python experiments/bench_env.py --batch 4 --steps 5 --repeats 2           # CPU smoke test
    python experiments/bench_env.py --tasks push --batch 4096 32768 \\
        --variant default --variant substeps=20,timestep=0.002 --variant iterations=2 --out bench.json
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import platform
import statistics
import sys
import time
from pathlib import Path

import jax
import jax.numpy as jnp

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

with contextlib.redirect_stdout(io.StringIO()):  # mujoco.mjx prints a note about warp on import
    import mujoco
    from mujoco import mjx  # noqa: F401

import envs  # noqa: E402
from envs.base import step_batch  # noqa: E402
from splid_jax.common.errors import InvalidConfig  # noqa: E402
from splid_jax.common.values import parse_overrides  # noqa: E402

TASKS = ["reach", "push", "slide", "pick_and_place", "reacher", "sawyer_door"]
GPU_BATCHES = [1024, 2048, 4096, 8192, 16384, 32768, 65536]
CPU_BATCHES = [16, 64]


def parse_variant(text: str) -> tuple[str, dict]:
    """``"default"`` or ``"substeps=20,timestep=0.002"`` -> (label, overrides)."""
    if text in ("", "default"):
        return "default", {}
    try:
        return text, parse_overrides(text, field="variant")
    except InvalidConfig as e:
        raise argparse.ArgumentTypeError(str(e)) from e


def make_program(env, steps: int):
    def run(state, key):
        def body(s, k):
            a = jax.random.uniform(k, (s.obs.shape[0], env.action_size), minval=-1.0, maxval=1.0)
            return step_batch(env, s, a), None  # one vmap, except on the CPU (envs.base.step_batch)

        state, _ = jax.lax.scan(body, state, jax.random.split(key, steps))
        return state

    return jax.jit(run)


def device_peak_bytes():
    stats = jax.devices()[0].memory_stats() or {}
    return stats.get("peak_bytes_in_use")


def bench_one(task: str, overrides: dict, batch: int, steps: int, repeats: int) -> dict:
    env = envs.make(task, **overrides)
    reset = jax.jit(jax.vmap(env.reset))
    state = jax.block_until_ready(reset(jax.random.split(jax.random.PRNGKey(0), batch)))
    program = make_program(env, steps)
    t0 = time.perf_counter()
    compiled = program.lower(state, jax.random.PRNGKey(1)).compile()
    compile_s = time.perf_counter() - t0
    mem = compiled.memory_analysis()
    times = []
    for r in range(repeats):
        key = jax.random.PRNGKey(2 + r)
        t0 = time.perf_counter()
        out = jax.block_until_ready(compiled(state, key))
        times.append(time.perf_counter() - t0)
    run_s = statistics.median(times)
    substeps = getattr(env, "substeps", getattr(env, "frame_skip", 1))  # physics steps per control step
    return {
        "task": task,
        "overrides": overrides,
        "batch": batch,
        "steps": steps,
        "substeps": substeps,
        "compile_s": compile_s,
        "run_s": run_s,
        "run_s_all": times,
        "control_steps_per_s": batch * steps / run_s,
        "physics_steps_per_s": batch * steps * substeps / run_s,
        "program_bytes": None
        if mem is None
        else {
            "arguments": mem.argument_size_in_bytes,
            "outputs": mem.output_size_in_bytes,
            "temporaries": mem.temp_size_in_bytes,
        },
        "device_peak_bytes": device_peak_bytes(),
        "invalid_envs": int(jnp.sum(out.invalid)),
    }


def _mib(x):
    return "-" if x is None else f"{x / 2**20:.1f}"


def markdown(rows: list[dict]) -> str:
    head = (
        "| task | variant | batch | compile s | run s (median) | control steps/s | physics steps/s "
        "| temp MiB | device peak MiB | note |\n|---|---|---|---|---|---|---|---|---|---|"
    )
    lines = [head]
    for r in rows:
        if "error" in r:
            lines.append(f"| {r['task']} | {r['variant']} | {r['batch']} | | | | | | | {r['error'][:60]} |")
            continue
        temp = r["program_bytes"]["temporaries"] if r["program_bytes"] else None
        note = f"{r['invalid_envs']} invalid" if r["invalid_envs"] else ""
        lines.append(
            f"| {r['task']} | {r['variant']} | {r['batch']} | {r['compile_s']:.1f} | {r['run_s']:.3f} "
            f"| {r['control_steps_per_s']:,.0f} | {r['physics_steps_per_s']:,.0f} | {_mib(temp)} "
            f"| {_mib(r['device_peak_bytes'])} | {note} |"
        )
    return "\n".join(lines)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(
        description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter
    )
    p.add_argument("--tasks", nargs="+", default=TASKS, choices=TASKS, help="tasks to time (default: all)")
    p.add_argument(
        "--batch",
        nargs="+",
        type=int,
        default=None,
        help=f"batch sizes (default {GPU_BATCHES} on GPU, {CPU_BATCHES} on CPU)",
    )
    p.add_argument("--steps", type=int, default=100, help="control steps per timed scan (default 100)")
    p.add_argument("--repeats", type=int, default=5, help="timed runs per setting; the median is reported")
    p.add_argument(
        "--variant",
        action="append",
        type=parse_variant,
        default=None,
        help="physics settings as task overrides, e.g. 'substeps=20,timestep=0.002' or 'iterations=2'; "
        "repeat the flag to compare several ('default' = the task's defaults; default: only that)",
    )
    p.add_argument("--out", type=Path, default=None, help="write the results as JSON to this path")
    args = p.parse_args(argv)
    if min(args.batch or [1]) < 1 or args.steps < 1 or args.repeats < 1:
        p.error("--batch, --steps and --repeats must be >= 1")
    backend = jax.default_backend()
    batches = sorted(args.batch or (GPU_BATCHES if backend == "gpu" else CPU_BATCHES))
    variants = args.variant or [("default", {})]
    for task in args.tasks:  # fail early, naming the field, before any compile
        for _, overrides in variants:
            try:
                envs.make(task, **overrides)
            except InvalidConfig as e:
                p.error(str(e))

    device = str(jax.devices()[0])
    print(f"device {device} ({backend}), jax {jax.__version__}, mujoco {mujoco.__version__}", flush=True)
    meta = {
        "device": device,
        "backend": backend,
        "jax": jax.__version__,
        "mujoco": mujoco.__version__,
        "host": platform.node(),
        "steps": args.steps,
        "repeats": args.repeats,
    }
    rows = []

    def save():  # after every row, so a run cut short by a time limit keeps what it measured
        if args.out:
            args.out.parent.mkdir(parents=True, exist_ok=True)
            args.out.write_text(json.dumps({"meta": meta, "results": rows}, indent=1))

    for task in args.tasks:
        for label, overrides in variants:
            for batch in batches:
                try:
                    row = bench_one(task, overrides, batch, args.steps, args.repeats)
                except Exception as e:  # e.g. out of device memory at a large batch
                    rows.append({"task": task, "variant": label, "batch": batch, "error": f"{type(e).__name__}: {e}"})
                    print(f"{task} {label} batch {batch}: {rows[-1]['error'][:200]}", flush=True)
                    save()
                    break
                row["variant"] = label
                rows.append(row)
                save()
                print(
                    f"{task} {label} batch {batch}: compile {row['compile_s']:.1f} s, "
                    f"{row['control_steps_per_s']:,.0f} control steps/s",
                    flush=True,
                )
    print()
    print(markdown(rows))
    if args.out:
        print(f"\nwrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
