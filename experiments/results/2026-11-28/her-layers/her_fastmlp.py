"""HER updates (5 vmapped seeds, Push): the MLP's per-feature parameters broadcast over the batch with a
backward that sums in two stages, against flax's own layers. python .gpu/her_fastmlp.py OUT_JSON"""

import json
import statistics
import sys
import time

import flax.linen as nn
import jax
import jax.numpy as jnp

from splid_jax.common.networks import MLP, Policy
from splid_jax.config import TrainConfig
from splid_jax.learners.registry import make_algorithm

CHUNK = 40


@jax.custom_vjp
def spread(p, x):
    return jnp.broadcast_to(p, x.shape).astype(x.dtype)


def _fwd(p, x):
    return spread(p, x), (p, jnp.zeros((0,), x.dtype))


def _bwd(res, g):
    p, x0 = res
    d = g.shape[-1]
    g = g.astype(jnp.float32).reshape(-1, d)
    n = g.shape[0]
    k = CHUNK if n % CHUNK == 0 else 1
    part = jax.lax.optimization_barrier(g.reshape(k, n // k, d).sum(1))
    return part.sum(0).astype(p.dtype), None


spread.defvjp(_fwd, _bwd)


class FastMLP(MLP):
    @nn.compact
    def __call__(self, x):
        act = getattr(nn, self.activation)
        for i, width in enumerate(self.hidden):
            x = nn.Dense(
                width,
                use_bias=False,
                kernel_init=nn.initializers.orthogonal(jnp.sqrt(2.0)),
                dtype=self.dtype,
                name=f"Dense_{i}",
            )(x)
            x = x + spread(self.param(f"bias_{i}", nn.initializers.zeros, (width,)), x)
            if self.layer_norm:
                x = nn.LayerNorm(use_scale=False, use_bias=False, dtype=self.dtype, name=f"LayerNorm_{i}")(x)
                x = x * spread(self.param(f"scale_{i}", nn.initializers.ones, (width,)), x)
                x = x + spread(self.param(f"shift_{i}", nn.initializers.zeros, (width,)), x)
            x = act(x)
        out_dtype = None if self.dtype is None else jnp.float32
        x = nn.Dense(
            self.action_size,
            kernel_init=nn.initializers.orthogonal(0.01),
            dtype=out_dtype,
            name=f"Dense_{len(self.hidden)}",
        )(x)
        return jnp.tanh(x) if self.tanh_output else x


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


res = {}
keys = jax.random.split(jax.random.PRNGKey(1), 5)
for opts in ("compute_dtype=bfloat16", ""):
    for fast in (False, True):
        cfg = TrainConfig(
            env=sys.argv[2] if len(sys.argv) > 2 else "push",
            algo="her",
            run_dir="/tmp/hf",
            her_options=",".join(o for o in (opts, *sys.argv[3:]) if o),
        )
        algo = make_algorithm(cfg, cfg.make_env())
        if fast:
            net = algo.policy.net
            kw = dict(hidden=net.hidden, activation=net.activation, layer_norm=net.layer_norm, dtype=net.dtype)
            algo.policy = Policy(
                net=FastMLP(**kw, action_size=net.action_size, tanh_output=True),
                in_size=algo.policy.in_size,
                normalise=True,
            )
            algo.critic = FastMLP(**kw, action_size=1)
        state = jax.vmap(algo.init)(jax.random.split(jax.random.PRNGKey(0), 5))
        it = jax.jit(jax.vmap(lambda s, a=algo: a.iteration(s, {})))
        for _ in range(16):
            state, m = it(state)
        row = timed(jax.jit(jax.vmap(algo.updates)), state, keys)
        row["critic_loss"] = float(jnp.mean(m["critic_loss"]))
        name = f"{opts or 'default precision'} {'two-stage sums' if fast else 'flax layers'}"
        res[name] = row
        print(name, row, flush=True)
        json.dump(res, open(sys.argv[1], "w"), indent=1)
