"""Which GPU kernels one control step of a task launches, and where their time goes.

At the batch sizes the learners step (HER's 16 to 80 envs, SPLID's 125) a control step is a chain of
small kernels whose count and per-kernel latency, not arithmetic, set its time. This traces a jitted
scan of ``--steps`` control steps (``bench_env``'s program) with ``jax.profiler`` and joins each
kernel of the trace to the HLO instruction that launched it (the compiled program's text), so the
kernels can be counted and timed by MuJoCo stage (MJX's named scopes, and the stages within them).

Per batch size it reports, per control step: wall ms (median of ``--repeats`` timed calls after a
warm-up, compile apart), GPU-busy ms (kernels' summed durations in the traced call), the kernel
count, the stages ranked by kernel time, and the costliest kernels.

    python experiments/kernel_profile.py --task push --batch 16 125 --out prof.json
    python experiments/kernel_profile.py --task push --batch 4 --steps 2 --repeats 1   # CPU smoke test
"""

from __future__ import annotations

import argparse
import collections
import glob
import gzip
import json
import re
import statistics
import sys
import tempfile
import time
from pathlib import Path

import jax

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from bench_env import make_program, parse_variant  # noqa: E402

import envs  # noqa: E402

# MJX's own named scopes (mujoco.mjx._src.forward), and the stages within them that ``scope_mjx`` names
STAGES = ("fwd_position", "fwd_velocity", "fwd_actuation", "fwd_acceleration", "euler", "implicit", "solve")
SCOPED = {
    "smooth": ("kinematics", "com_pos", "com_vel", "crb", "factor_m", "transmission", "rne", "tendon", "tendon_bias"),
    "collision_driver": ("collision",),
    "constraint": ("make_constraint",),
    "passive": ("passive",),
    "solver": ("solve",),
}
_INSTRUCTION = re.compile(r"^\s*(?:ROOT\s+)?%?([\w.\-]+) = .*?metadata=\{([^}]*)\}")
_FIELD = re.compile(r'(\w+)="([^"]*)"|(\w+)=(\d+)')


def scope_mjx() -> tuple[str, ...]:
    """Wrap MJX's stage functions in named scopes, so that each kernel's op name says its stage.

    ``mujoco.mjx._src.forward`` calls them through their modules, so replacing the module attributes
    reaches every call; the computation is unchanged. Returns every stage name, outermost first."""
    import importlib

    names = list(STAGES)
    for module, fns in SCOPED.items():
        mod = importlib.import_module(f"mujoco.mjx._src.{module}")
        for fn in fns:
            if not hasattr(mod, fn):
                continue
            if not getattr(getattr(mod, fn), "_scoped", False):
                wrapped = jax.named_scope(fn)(getattr(mod, fn))
                wrapped._scoped = True
                setattr(mod, fn, wrapped)
            names.append(fn)
    return tuple(dict.fromkeys(names))


def _key(name: str) -> str:
    return re.sub(r"[.\-]", "_", name)


def instruction_sources(hlo_text: str) -> dict[str, dict]:
    """Each instruction's op name and source file, keyed by its name as kernels are named."""
    out = {}
    for line in hlo_text.splitlines():
        m = _INSTRUCTION.match(line)
        if not m:
            continue
        meta = {}
        for f in _FIELD.finditer(m.group(2)):
            if f.group(1):
                meta[f.group(1)] = f.group(2)
            else:
                meta[f.group(3)] = f.group(4)
        out[_key(m.group(1))] = meta
    return out


def stage_of(op_name: str, stages: tuple[str, ...] = STAGES) -> str:
    parts = re.split(r"[/()]", op_name)
    found = [p for p in parts if p in stages]
    return found[-1] if found else "outside mjx.step"


def kernel_events(trace_dir: str) -> list[dict]:
    """The GPU's kernel events of a ``jax.profiler`` trace (stream lines of the device processes)."""
    (path,) = glob.glob(f"{trace_dir}/**/perfetto_trace.json.gz", recursive=True)
    data = json.load(gzip.open(path))
    events = data["traceEvents"] if isinstance(data, dict) else data
    procs = {e["pid"]: e["args"]["name"] for e in events if e.get("ph") == "M" and e.get("name") == "process_name"}
    threads = {
        (e["pid"], e["tid"]): e["args"]["name"] for e in events if e.get("ph") == "M" and e.get("name") == "thread_name"
    }
    gpu = {pid for pid, name in procs.items() if "GPU" in name or "gpu" in name}
    return [
        e
        for e in events
        if e.get("ph") == "X"
        and e.get("pid") in gpu
        and threads.get((e["pid"], e.get("tid")), "").startswith("Stream")
        and "Memcpy" not in e["name"]
        and "Memset" not in e["name"]
    ]


def profile_one(task: str, overrides: dict, batch: int, steps: int, repeats: int, top: int) -> dict:
    stages = scope_mjx()
    env = envs.make(task, **overrides)
    reset = jax.jit(jax.vmap(env.reset))
    state = jax.block_until_ready(reset(jax.random.split(jax.random.PRNGKey(0), batch)))
    t0 = time.perf_counter()
    compiled = make_program(env, steps).lower(state, jax.random.PRNGKey(1)).compile()
    compile_s = time.perf_counter() - t0
    jax.block_until_ready(compiled(state, jax.random.PRNGKey(1)))  # warm-up
    times = []
    for r in range(repeats):
        t0 = time.perf_counter()
        jax.block_until_ready(compiled(state, jax.random.PRNGKey(2 + r)))
        times.append(time.perf_counter() - t0)
    with tempfile.TemporaryDirectory() as d:
        with jax.profiler.trace(d, create_perfetto_trace=True):
            jax.block_until_ready(compiled(state, jax.random.PRNGKey(2)))
        kernels = kernel_events(d)
    sources = instruction_sources(compiled.as_text())
    by_stage: dict = collections.defaultdict(lambda: [0, 0.0])
    by_kernel: dict = collections.defaultdict(lambda: [0, 0.0, "", ""])
    unmatched = 0
    for e in kernels:
        meta = sources.get(_key(e["name"]))
        if meta is None:
            unmatched += 1
            meta = {}
        stage = stage_of(meta.get("op_name", ""), stages)
        by_stage[stage][0] += 1
        by_stage[stage][1] += e["dur"]
        row = by_kernel[e["name"]]
        row[0] += 1
        row[1] += e["dur"]
        row[2], row[3] = stage, meta.get("op_name", "?")[-80:]

    def ranked(table, n=None):
        rows = sorted(table.items(), key=lambda kv: -kv[1][1])[:n]
        return [
            {
                "name": k,
                "kernels_per_step": v[0] / steps,
                "us_per_step": v[1] / steps,
                **({"stage": v[2], "op_name": v[3]} if len(v) > 2 else {}),
            }
            for k, v in rows
        ]

    busy_us = sum(e["dur"] for e in kernels)
    return {
        "task": task,
        "overrides": overrides,
        "batch": batch,
        "steps": steps,
        "compile_s": compile_s,
        "wall_ms_per_step": 1e3 * statistics.median(times) / steps,
        "gpu_busy_ms_per_step": busy_us / 1e3 / steps,
        "kernels_per_step": len(kernels) / steps,
        "kernels_not_joined": unmatched,
        "by_stage": ranked(by_stage),
        "top_kernels": ranked(by_kernel, top),
    }


def markdown(r: dict) -> str:
    lines = [
        f"### {r['task']} {r['overrides'] or ''} batch {r['batch']}: wall {r['wall_ms_per_step']:.3f} ms per "
        f"control step, kernels busy {r['gpu_busy_ms_per_step']:.3f} ms, {r['kernels_per_step']:.0f} kernels "
        f"(compile {r['compile_s']:.1f} s; {r['kernels_not_joined']} kernels not joined to an instruction)",
        "",
        "| stage (innermost) | kernels per step | us per step |",
        "|---|---:|---:|",
    ]
    for row in r["by_stage"]:
        lines.append(f"| {row['name']} | {row['kernels_per_step']:.0f} | {row['us_per_step']:.0f} |")
    lines += ["", "| kernel | stage | op name (its end) | per step | us per step |", "|---|---|---|---:|---:|"]
    for row in r["top_kernels"]:
        lines.append(
            f"| {row['name'][:60]} | {row['stage']} | {row['op_name']} | {row['kernels_per_step']:.1f} "
            f"| {row['us_per_step']:.1f} |"
        )
    return "\n".join(lines)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(
        description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter
    )
    p.add_argument("--task", default="push", help="task name (default push)")
    p.add_argument("--batch", nargs="+", type=int, default=[16, 125], help="batch sizes (default 16 125)")
    p.add_argument("--steps", type=int, default=20, help="control steps in the traced scan (default 20)")
    p.add_argument("--repeats", type=int, default=5, help="timed calls; the median is reported")
    p.add_argument("--top", type=int, default=25, help="kernels listed (default 25)")
    p.add_argument(
        "--variant", type=parse_variant, default=("default", {}), help="task overrides, e.g. solver_loops=search"
    )
    p.add_argument("--out", type=Path, default=None, help="write the results as JSON here (and .md beside it)")
    args = p.parse_args(argv)
    if min(args.batch) < 1 or args.steps < 1 or args.repeats < 1:
        p.error("--batch, --steps and --repeats must be >= 1")
    print(f"device {jax.devices()[0]}, jax {jax.__version__}", flush=True)
    if jax.default_backend() != "gpu":
        print("no GPU: the trace holds no kernels, so only the wall times below mean anything", flush=True)
    results = []
    for batch in args.batch:
        results.append(profile_one(args.task, args.variant[1], batch, args.steps, args.repeats, args.top))
        print(markdown(results[-1]), flush=True)
        if args.out:
            args.out.parent.mkdir(parents=True, exist_ok=True)
            args.out.write_text(json.dumps({"device": str(jax.devices()[0]), "results": results}, indent=1))
            args.out.with_suffix(".md").write_text("\n\n".join(markdown(r) for r in results) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
