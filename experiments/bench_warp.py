"""Push's physics under MJX's Warp backend (``mjx.put_model(..., impl="warp")``) against the JAX one the
trainer uses, at small batches, and whether restoring a saved state and replaying it is exact.

For each batch a jitted ``lax.scan`` of ``--steps`` control steps (each ``substeps`` MJX steps, 10 for
Push) is compiled for each implementation; its inputs are the batched state and the actions, its
outputs the final state and the qpos/qvel after every control step. The actions are uniform in [-1, 1]
and turned into controls by the task's own ``_action`` and ``_control`` (as ``env.step`` does), so both implementations
get the same actions and the same control law.

- ``jax``: the trainer's step, ``env.simulate`` (MJX's JAX implementation with the task's written-out
  solver loops and Cholesky), carrying ``Physics`` (qpos, qvel, ctrl, time, qacc_warmstart).
- ``warp``: ``jax.vmap(mjx.step)`` over a warp ``Data`` made by ``mjx.make_data(mj_model, impl="warp")``
  for one world and batched by ``vmap`` (contact arrays are shared by all worlds: ``naconmax`` is
  ``batch * --nconmax``), carried whole. One Warp FFI call per MJX step, captured as a CUDA graph
  per ``--graph-mode`` (mjx's default: WARP on a GPU, JAX on the CPU).

Each program runs once from the reset states with actions A0 (the warm-up; its time, with the Warp
kernels' first build, is ``first run s``), which leaves a mid-episode state S. Then ``--repeats`` timed
runs from S with actions A1; ``run s`` is their median (``block_until_ready``), compile time apart.

Exactness: ``replay`` is the largest |qpos|/|qvel| difference over the whole trajectory between the
timed runs from S (a saved state restored and replayed with the same actions; 0 means exact);
for warp, ``restore from physics`` replays from a fresh warp Data holding only S's qpos, qvel, ctrl,
time and qacc_warmstart (what the trainer's ``State`` keeps). ``jax - warp`` is the difference of the
two implementations' warm-up trajectories (same reset states, same actions) after 1 and 50 control
steps, reported, not judged: where Push's cap of 4 Newton iterations cuts the solve short the two
backends stop at different iterates, so ``--warp-iterations`` sets Warp's cap alone, to time it at equal
physics too (experiments/NOTES.md, "MJX's Warp backend"). Warp's overflow bits (``OverflowType``) after
the last run are listed when any is set. Warp's CPU kernels need warp/bin/warp-clang.so, which a
CUDA-only install may drop.

Examples::

    python experiments/bench_warp.py --batch 4 --steps 5 --repeats 2          # CPU smoke test
    python experiments/bench_warp.py --batch 16 125 1024 --graph-mode WARP JAX --out warp.json
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import functools
import importlib.util
import io
import json
import platform
import statistics
import sys
import time
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

with contextlib.redirect_stdout(io.StringIO()):  # mujoco.mjx prints a note when warp is missing
    import mujoco
    from mujoco import mjx

import envs  # noqa: E402
from splid_jax.common.errors import InvalidConfig  # noqa: E402
from splid_jax.common.values import parse_overrides  # noqa: E402

GPU_BATCHES = [16, 125, 1024]
CPU_BATCHES = [4]
GRAPH_MODES = ["default", "NONE", "JAX", "WARP", "WARP_STAGED", "WARP_STAGED_EX"]
DRIFT_STEPS = (1, 50)  # control steps after which the jax and warp trajectories are compared


def missing_warp() -> str | None:
    """A line naming the missing package when MJX's warp backend can't be imported, else None; imports
    nothing from warp when it is absent."""
    if importlib.util.find_spec("warp") is None:
        return "warp-lang is not installed (no module 'warp'); MJX's impl='warp' needs it"
    if importlib.util.find_spec("mujoco.mjx.third_party.mujoco_warp") is None:
        return f"mujoco-mjx {mujoco.__version__} ships no mujoco.mjx.third_party.mujoco_warp (MJX's Warp backend)"
    with contextlib.redirect_stdout(io.StringIO()) as out:
        import mujoco.mjx.warp as mjxw
    if not mjxw.WARP_INSTALLED:
        return f"warp-lang is installed but fails to import: {out.getvalue().strip()}"
    return None


@functools.lru_cache(maxsize=8)
def physics_cls(env):
    """The task's ``Physics`` struct (qpos, qvel, ctrl, time, qacc_warmstart for the Fetch tasks)."""
    return type(env.reset(jax.random.PRNGKey(0)).physics)


def physics_names(env) -> list[str]:
    return [f.name for f in dataclasses.fields(physics_cls(env))]


def jax_program(env):
    """(physics, actions[steps, B, 4]) -> (physics, qpos[steps, B, nq], qvel[steps, B, nv])."""

    def one(phys, action):
        return env.simulate(phys, env._control(phys, env._action(action)))

    def run(phys, actions):
        def body(p, a):
            p = jax.vmap(one)(p, a)
            return p, (p.qpos, p.qvel)

        phys, (qpos, qvel) = jax.lax.scan(body, phys, actions)
        return phys, qpos, qvel

    return jax.jit(run)


def warp_program(env, mw, names: list[str]):
    """(warp Data batched, actions[steps, B, 4]) -> (Data, qpos[steps, B, nq], qvel[steps, B, nv])."""
    phys_cls = physics_cls(env)
    step = jax.vmap(mjx.step, in_axes=(None, 0))

    def run(d, actions):
        def body(d, a):
            phys = phys_cls(**{n: getattr(d, n) for n in names})
            ctrl = jax.vmap(env._control)(phys, env._action(a))
            d = jax.lax.fori_loop(0, env.substeps, lambda _, x: step(mw, x), d.replace(ctrl=ctrl))
            return d, (d.qpos, d.qvel)

        d, (qpos, qvel) = jax.lax.scan(body, d, actions)
        return d, qpos, qvel

    return jax.jit(run)


def quiet_iterations(mw, keep: bool):
    """``mw`` without Warp's printed warning when the solver or its line search ends at its iteration limit
    (Push's 4 and 4 end there often; the overflow bits are still set and reported); the JAX solver stops
    there silently."""
    if keep:
        return mw
    from mujoco.mjx.third_party.mujoco_warp._src.types import OverflowType

    impl = mw.opt._impl
    mask = int(impl.warn_overflow) & ~int(OverflowType.ITERATIONS | OverflowType.LS_ITERATIONS)
    return mw.replace(opt=mw.opt.replace(_impl=impl.replace(warn_overflow=mask)))


def warp_data(template, phys, names: list[str]):
    """A batched warp Data: the one-world ``template`` with ``phys``'s fields (batched) set."""
    return jax.jit(jax.vmap(lambda p: template.replace(**{n: getattr(p, n) for n in names})))(phys)


def max_abs(a, b) -> float:
    return float(jnp.max(jnp.abs(jnp.asarray(a, jnp.float32) - jnp.asarray(b, jnp.float32))))


def traj_diff(t0, t1) -> dict:
    return {"qpos": max_abs(t0[0], t1[0]), "qvel": max_abs(t0[1], t1[1])}


def overflow_names(d) -> list[str]:
    from mujoco.mjx.third_party.mujoco_warp._src.types import OverflowType

    bits = int(np.bitwise_or.reduce(np.asarray(d._impl.overflow).ravel()))
    return [f.name for f in OverflowType if f.value and f.value != OverflowType.ALL and bits & f.value]


def compile_timed(program, state, actions):
    """(seconds to lower and compile, the compiled program)."""
    t0 = time.perf_counter()
    compiled = program.lower(state, actions).compile()
    return time.perf_counter() - t0, compiled


def run_repeats(compiled, state, actions, repeats: int):
    times, trajs, out = [], [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = jax.block_until_ready(compiled(state, actions))
        times.append(time.perf_counter() - t0)
        trajs.append((np.asarray(out[1]), np.asarray(out[2])))
    return times, trajs, out


def replay_diff(trajs) -> dict:
    diffs = [traj_diff(trajs[0], t) for t in trajs[1:]] or [{"qpos": 0.0, "qvel": 0.0}]
    return {k: max(d[k] for d in diffs) for k in ("qpos", "qvel")}


def row_of(impl, mode, batch, steps, substeps, compile_s, first_s, times) -> dict:
    run_s = statistics.median(times)
    return {
        "impl": impl,
        "graph_mode": mode,
        "batch": batch,
        "steps": steps,
        "substeps": substeps,
        "compile_s": compile_s,
        "first_run_s": first_s,
        "run_s": run_s,
        "run_s_all": times,
        "ms_per_control_step": 1e3 * run_s / steps,
        "control_steps_per_s": batch * steps / run_s,
        "physics_steps_per_s": batch * steps * substeps / run_s,
    }


def bench_batch(env, batch: int, args, modes: list[str], emit) -> list[dict]:
    """``emit``s a row per implementation and graph mode as each ends; returns the drift rows (one per
    warp graph mode, when jax ran too)."""
    names = physics_names(env)
    steps, substeps = args.steps, env.substeps
    key = jax.random.PRNGKey(args.seed)
    k_reset, k0, k1 = jax.random.split(key, 3)
    state0 = jax.jit(jax.vmap(env.reset))(jax.random.split(k_reset, batch))
    phys0 = jax.block_until_ready(state0.physics)
    a0 = jax.random.uniform(k0, (steps, batch, env.action_size), minval=-1.0, maxval=1.0)
    a1 = jax.random.uniform(k1, (steps, batch, env.action_size), minval=-1.0, maxval=1.0)
    drifts = []
    jax_traj0 = None

    if "jax" in args.impl:
        try:
            program = jax_program(env)
            compile_s, compiled = compile_timed(program, phys0, a0)
            t0 = time.perf_counter()
            mid, qpos, qvel = jax.block_until_ready(compiled(phys0, a0))
            first_s = time.perf_counter() - t0
            jax_traj0 = (np.asarray(qpos), np.asarray(qvel))
            times, trajs, _ = run_repeats(compiled, mid, a1, args.repeats)
            row = row_of("jax", "-", batch, steps, substeps, compile_s, first_s, times)
            row["iterations"] = env.iterations
            row["replay_max_abs"] = replay_diff(trajs)
        except Exception as e:  # e.g. out of device memory
            row = {
                "impl": "jax",
                "graph_mode": "-",
                "iterations": env.iterations,
                "batch": batch,
                "error": f"{type(e).__name__}: {e}",
            }
        emit(row)

    if "warp" in args.impl:
        for iterations in args.warp_iterations or [env.iterations]:
            env_w = dataclasses.replace(env, iterations=iterations)  # the same task, its solver capped there
            template = mjx.make_data(env_w.mj_model, impl="warp", naconmax=batch * args.nconmax, njmax=args.njmax)
            d0 = warp_data(template, phys0, names)
            for mode in modes:
                try:
                    row, warp_traj0 = bench_warp(env_w, mode, template, d0, a0, a1, args)
                    if jax_traj0 is not None:
                        drift = {"batch": batch, "graph_mode": row["graph_mode"], "iterations": iterations}
                        for s in DRIFT_STEPS:
                            s = min(s, steps)
                            drift[f"after_{s}"] = traj_diff(
                                (jax_traj0[0][s - 1], jax_traj0[1][s - 1]),
                                (warp_traj0[0][s - 1], warp_traj0[1][s - 1]),
                            )
                        drifts.append(drift)
                except Exception as e:
                    row = {"impl": "warp", "graph_mode": mode, "iterations": iterations, "batch": batch}
                    row["error"] = f"{type(e).__name__}: {e}"
                emit(row)
    return drifts


def bench_warp(env, mode: str, template, d0, a0, a1, args) -> tuple[dict, tuple]:
    """The warp row for one graph mode, and its warm-up trajectory (qpos, qvel)."""
    from mujoco.mjx.warp import types as mjxw_types

    names = physics_names(env)
    batch, steps = d0.qpos.shape[0], a0.shape[0]
    kw = {} if mode == "default" else {"graph_mode": getattr(mjxw_types.GraphMode, mode)}
    mw = quiet_iterations(mjx.put_model(env.mj_model, impl="warp", **kw), args.warn_iterations)
    chosen = mjxw_types.GraphMode(mw.opt._impl.graph_mode).name
    program = warp_program(env, mw, names)
    compile_s, compiled = compile_timed(program, d0, a0)
    t0 = time.perf_counter()
    mid, qpos, qvel = jax.block_until_ready(compiled(d0, a0))
    first_s = time.perf_counter() - t0
    times, trajs, out = run_repeats(compiled, mid, a1, args.repeats)
    label = mode if mode != "default" else f"default ({chosen})"
    row = row_of("warp", label, batch, steps, env.substeps, compile_s, first_s, times)
    row["iterations"] = env.iterations
    row["replay_max_abs"] = replay_diff(trajs)
    fresh = warp_data(template, physics_cls(env)(**{n: getattr(mid, n) for n in names}), names)
    _, qpos_f, qvel_f = jax.block_until_ready(compiled(fresh, a1))
    row["restore_from_physics_max_abs"] = traj_diff(trajs[0], (np.asarray(qpos_f), np.asarray(qvel_f)))
    row["overflow"] = overflow_names(out[0])
    row["nacon_last"] = int(np.asarray(out[0]._impl.nacon).ravel()[0])
    row["naconmax"] = batch * args.nconmax
    row["njmax"] = args.njmax
    return row, (np.asarray(qpos), np.asarray(qvel))


def _pair(d: dict | None) -> str:
    return "-" if d is None else f"{d['qpos']:.2g} / {d['qvel']:.2g}"


def markdown(rows: list[dict], drifts: list[dict]) -> str:
    lines = [
        "| impl | graph mode | iterations | batch | compile s | first run s | ms / control step | control steps/s "
        "| replay max abs qpos / qvel | restore from physics | note |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        if "error" in r:
            head = f"| {r['impl']} | {r['graph_mode']} | {r['iterations']} | {r['batch']} |"
            lines.append(f"{head} | | | | | | {r['error'][:80]} |")
            continue
        note = ", ".join(r.get("overflow", []))
        lines.append(
            f"| {r['impl']} | {r['graph_mode']} | {r['iterations']} | {r['batch']} "
            f"| {r['compile_s']:.1f} | {r['first_run_s']:.1f} "
            f"| {r['ms_per_control_step']:.3f} | {r['control_steps_per_s']:,.0f} | {_pair(r['replay_max_abs'])} "
            f"| {_pair(r.get('restore_from_physics_max_abs'))} | {note} |"
        )
    if drifts:
        keys = [k for k in drifts[0] if k.startswith("after_")]
        cols = " | ".join(f"jax - warp after {k.split('_')[1]} control steps, max abs qpos / qvel" for k in keys)
        lines += ["", f"| warp graph mode | warp iterations | batch | {cols} |", "|---|---|---|" + "---|" * len(keys)]
        for d in drifts:
            lines.append(
                f"| {d['graph_mode']} | {d['iterations']} | {d['batch']} | "
                + " | ".join(_pair(d[k]) for k in keys)
                + " |"
            )
    return "\n".join(lines)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(
        description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter
    )
    p.add_argument("--task", default="push", choices=["reach", "push", "slide", "pick_and_place"])
    p.add_argument("--options", default="", help="task field overrides, e.g. 'substeps=20,timestep=0.002'")
    p.add_argument(
        "--batch",
        nargs="+",
        type=int,
        default=None,
        help=f"batches (default {GPU_BATCHES} on GPU, {CPU_BATCHES} on CPU)",
    )
    p.add_argument("--steps", type=int, default=100, help="control steps per timed scan (default 100)")
    p.add_argument("--repeats", type=int, default=5, help="timed runs per setting; the median is reported")
    p.add_argument("--impl", nargs="+", default=["jax", "warp"], choices=["jax", "warp"])
    p.add_argument(
        "--graph-mode",
        nargs="+",
        default=["default"],
        choices=GRAPH_MODES,
        help="Warp's CUDA graph modes to time (warp.JaxCallableGraphMode; default: mjx's choice)",
    )
    p.add_argument(
        "--warp-iterations",
        nargs="+",
        type=int,
        default=None,
        help="the warp model's Newton iteration caps to time (default: the task's). At Push's 4 the solve is cut "
        "short in some states, where Warp's iterates differ from MuJoCo's and MJX's (which agree); at 10 all agree",
    )
    p.add_argument(
        "--nconmax", type=int, default=48, help="warp contacts allocated per world (naconmax = batch x this)"
    )
    p.add_argument("--njmax", type=int, default=64, help="warp constraint rows allocated per world")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--warp-cache", default=None, help="Warp's kernel cache folder (default: Warp's own)")
    p.add_argument("--warp-verbose", action="store_true", help="let Warp print its module builds")
    p.add_argument(
        "--warn-iterations", action="store_true", help="keep Warp's printed warning at the solver's iteration limit"
    )
    p.add_argument("--out", type=Path, default=None, help="write the results as JSON to this path")
    args = p.parse_args(argv)
    if min(args.batch or [1]) < 1 or min(args.warp_iterations or [1]) < 1 or args.steps < 1 or args.repeats < 1:
        p.error("--batch, --warp-iterations, --steps and --repeats must be >= 1")
    try:
        env = envs.make(args.task, **parse_overrides(args.options, field="options"))
    except InvalidConfig as e:
        p.error(str(e))
    if "warp" in args.impl:
        missing = missing_warp()
        if missing:
            print(missing)
            return 2
        import warp

        if not args.warp_verbose:  # Warp logs each module's build and load
            warp.config.log_level = getattr(warp, "LOG_WARNING", 30)
            warp.config.quiet = True  # the older switch
        if args.warp_cache:
            warp.config.kernel_cache_dir = args.warp_cache

    backend = jax.default_backend()
    batches = sorted(args.batch or (GPU_BATCHES if backend == "gpu" else CPU_BATCHES))
    device = str(jax.devices()[0])
    meta = {
        "device": device,
        "backend": backend,
        "jax": jax.__version__,
        "mujoco": mujoco.__version__,
        "warp": None,
        "host": platform.node(),
        "task": args.task,
        "options": args.options,
        "substeps": env.substeps,
        "steps": args.steps,
        "repeats": args.repeats,
        "seed": args.seed,
    }
    if "warp" in args.impl:
        import warp

        meta["warp"] = warp.__version__
    print(f"device {device} ({backend}), jax {jax.__version__}, mujoco {mujoco.__version__}, warp {meta['warp']}")
    rows, drifts = [], []

    def save():  # after every row, so a run cut short by a time limit keeps what it measured
        if args.out:
            args.out.parent.mkdir(parents=True, exist_ok=True)
            args.out.write_text(json.dumps({"meta": meta, "results": rows, "drift": drifts}, indent=1))

    def log(row):
        what = f"{row['impl']} {row['graph_mode']} iterations {row['iterations']} batch {row['batch']}"
        if "error" in row:
            print(f"{what}: {row['error'][:300]}", flush=True)
        else:
            print(
                f"{what}: compile {row['compile_s']:.1f} s, "
                f"first run {row['first_run_s']:.1f} s, {row['ms_per_control_step']:.3f} ms / control step, "
                f"replay {_pair(row['replay_max_abs'])}",
                flush=True,
            )

    def emit(row):
        rows.append(row)
        save()
        log(row)

    for batch in batches:
        drifts.extend(bench_batch(env, batch, args, args.graph_mode, emit))
        save()
    print()
    print(markdown(rows, drifts))
    if args.out:
        print(f"\nwrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
