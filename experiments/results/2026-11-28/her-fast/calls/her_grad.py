"""HER (mrl settings, bf16) on Push, 5 vmapped seeds: updates and explore timed, and a kernel profile
of the updates with each kernel's full op name.

    python experiments/results/2026-11-28/her-fast/calls/her_grad.py OUT_JSON [TRACE_DIR]
"""

import collections
import json
import os
import statistics
import sys
import tempfile
import time

import jax

sys.path.insert(0, "experiments")
from kernel_profile import instruction_sources, kernel_events  # noqa: E402

from splid_jax.config import TrainConfig  # noqa: E402
from splid_jax.learners.registry import make_algorithm  # noqa: E402

if os.environ.get("VARIANT") == "fastln":
    sys.path.insert(0, "experiments/results/2026-11-28/her-fast/calls")
    from fast_ln import FastLayerNorm

    import splid_jax.common.networks as nw

    nw.LayerNorm = FastLayerNorm

out_path = sys.argv[1]
SEEDS = 5
res = {"devices": str(jax.devices()), "xla_flags": os.environ.get("XLA_FLAGS", "")}


def save():
    return json.dump(res, open(out_path, "w"), indent=1)


def timed(fn, *args, repeats=7):
    t0 = time.perf_counter()
    jax.block_until_ready(fn(*args))
    first = time.perf_counter() - t0
    ts = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        jax.block_until_ready(fn(*args))
        ts.append(time.perf_counter() - t0)
    med = statistics.median(ts)
    return {"median_ms": med * 1e3, "min_ms": min(ts) * 1e3, "compile_s": first - med}


def build(num_envs):
    opts = ",".join(o for o in ("compute_dtype=bfloat16", os.environ.get("EXTRA", "")) if o)
    cfg = TrainConfig(
        env=os.environ.get("ENV", "push"), algo="her", run_dir="/tmp/hg", num_envs=num_envs, her_options=opts
    )
    return make_algorithm(cfg, cfg.make_env())


keys = jax.random.split(jax.random.PRNGKey(1), SEEDS)
for n in tuple(int(x) for x in os.environ.get("ENVS", "8,16,32").split(",")):
    algo = build(n)
    state = jax.vmap(algo.init)(jax.random.split(jax.random.PRNGKey(0), SEEDS))
    it = jax.jit(jax.vmap(lambda s, a=algo: a.iteration(s, {})))
    for _ in range(max(2, 128 // n)):
        state, _ = it(state)
    state = jax.block_until_ready(state)
    res[f"updates_{n}_only"] = timed(jax.jit(jax.vmap(algo.updates)), state, keys)
    res[f"explore_{n}"] = timed(jax.jit(jax.vmap(lambda s, k, a=algo: a.explore(s.policy, k))), state, keys)
    res[f"iteration_{n}"] = timed(it, state, repeats=5)
    res[f"iteration_{n}"]["updates"] = algo.n_updates
    if n == 8 and os.environ.get("PROFILE", "1") == "1":
        upd = jax.jit(jax.vmap(algo.updates))
        res["updates_8"] = timed(upd, state, keys)
        compiled = upd.lower(state, keys).compile()
        src = instruction_sources(compiled.as_text())
        jax.block_until_ready(compiled(state, keys))
        trace = sys.argv[2] if len(sys.argv) > 2 else tempfile.mkdtemp()
        with jax.profiler.trace(trace, create_perfetto_trace=True):
            jax.block_until_ready(compiled(state, keys))
        try:
            events = kernel_events(trace)
        except ValueError:
            events = []
        by_kernel, count, by_op = collections.Counter(), collections.Counter(), collections.Counter()
        for e in events:
            name = e["name"]
            by_kernel[name] += e["dur"]
            count[name] += 1
            meta = src.get(name.split(".")[0].replace("-", "_"), src.get(name.replace(".", "_").replace("-", "_"), {}))
            by_op[meta.get("op_name", "?")[-160:]] += e["dur"]
        res["profile"] = {
            "kernels": len(events),
            "busy_ms": sum(e["dur"] for e in events) / 1e3,
            "top_kernels": [(k, v / 1e3, count[k]) for k, v in by_kernel.most_common(50)],
            "top_ops": [(k, v / 1e3) for k, v in by_op.most_common(60)],
        }
    print(n, {k: v for k, v in res.items() if k.endswith(f"_{n}")}, flush=True)
    save()
save()
