"""HER (mrl settings) on Push, 5 vmapped seeds: explore and updates timed per variant, and a kernel profile.

python .gpu/her_speed.py OUT_JSON [TRACE_DIR]"""

import collections
import importlib.util
import json
import os
import statistics
import sys
import tempfile
import time

import jax
import optax

sys.path.insert(0, "experiments")
from kernel_profile import instruction_sources, kernel_events  # noqa: E402

from splid_jax.config import TrainConfig  # noqa: E402
from splid_jax.learners.registry import make_algorithm  # noqa: E402

out_path = sys.argv[1]
SEEDS = 5
ENV = os.environ.get("ENV", "push")
EXTRA = os.environ.get("EXTRA", "")
res = {"devices": str(jax.devices())}


def save():
    json.dump(res, open(out_path, "w"), indent=1)


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


def build(her_options="", flatten=False, old=False):
    opts = ",".join(o for o in (her_options, EXTRA) if o)
    cfg = TrainConfig(env=ENV, algo="her", run_dir="/tmp/hs", her_options=opts)
    algo = make_algorithm(cfg, cfg.make_env())
    if flatten:
        algo.actor_opt = optax.flatten(optax.adam(algo.her.actor_lr))
        algo.critic_opt = optax.flatten(optax.adam(algo.her.critic_lr))
    if old:
        spec = importlib.util.spec_from_file_location("old_learner", ".gpu/old_learner.py")
        mod = importlib.util.module_from_spec(spec)
        sys.modules["old_learner"] = mod
        spec.loader.exec_module(mod)
        algo._updates = mod.HER._updates.__get__(algo)
    return cfg, algo


def warm_state(algo):
    state = jax.vmap(algo.init)(jax.random.split(jax.random.PRNGKey(0), SEEDS))
    it = jax.jit(jax.vmap(lambda s: algo.iteration(s, {})))
    for _ in range(16):  # 128 episodes, 6,400 transitions: past the 5,000-step warm-up
        state, _ = it(state)
    return jax.block_until_ready(state)


keys = jax.random.split(jax.random.PRNGKey(1), SEEDS)
variants = [
    ("old per-step targets, default precision", dict(old=True)),
    ("blocks, default precision", dict()),
    ("blocks, bf16", dict(her_options="compute_dtype=bfloat16")),
    ("blocks, bf16, flattened Adam", dict(her_options="compute_dtype=bfloat16", flatten=True)),
    ("blocks, float32", dict(her_options="matmul_precision=float32")),
]
states = {}
if os.environ.get("PROFILE_ONLY"):
    variants = variants[1:2]
for name, kw in variants:
    cfg, algo = build(**kw)
    flat = bool(kw.get("flatten"))
    if flat not in states:
        state = states[flat] = warm_state(algo)
        res[f"explore{' flat' if flat else ''}"] = timed(
            jax.jit(jax.vmap(lambda s, k, a=algo: a.explore(s.policy, k))), state, keys
        )
        res[f"iteration_whole{' flat' if flat else ''}"] = timed(
            jax.jit(jax.vmap(lambda s, a=algo: a.iteration(s, {}))), state, repeats=5
        )
    state = states[flat]
    upd = jax.jit(jax.vmap(algo.updates))
    row = timed(upd, state, keys)
    row["steps"] = algo.n_updates
    res[name] = row
    print(name, row, flush=True)
    save()

# profile: the bf16 blocks' updates
state = states[False]
cfg, algo = build(her_options="compute_dtype=bfloat16")
upd = jax.jit(jax.vmap(algo.updates))
compiled = upd.lower(state, keys).compile()
src = instruction_sources(compiled.as_text())
jax.block_until_ready(compiled(state, keys))
trace = sys.argv[2] if len(sys.argv) > 2 else tempfile.mkdtemp()
with jax.profiler.trace(trace, create_perfetto_trace=True):
    jax.block_until_ready(compiled(state, keys))
try:
    events = kernel_events(trace)
except ValueError:  # no GPU trace (a CPU run)
    events = []
total = sum(e["dur"] for e in events)
by_kernel = collections.Counter()
count = collections.Counter()
by_op = collections.Counter()
for e in events:
    name = e["name"]
    by_kernel[name] += e["dur"]
    count[name] += 1
    meta = src.get(name.split(".")[0].replace("-", "_"), src.get(name.replace(".", "_").replace("-", "_"), {}))
    op = meta.get("op_name", "?")
    by_op["/".join(op.split("/")[:6])[-120:]] += e["dur"]
res["profile"] = {
    "kernels": len(events),
    "busy_ms": total / 1e3,
    "top_kernels": [(k, v / 1e3, count[k]) for k, v in by_kernel.most_common(40)],
    "top_ops": [(k, v / 1e3) for k, v in by_op.most_common(40)],
}
save()
print(json.dumps(res["profile"], indent=1)[:6000])
