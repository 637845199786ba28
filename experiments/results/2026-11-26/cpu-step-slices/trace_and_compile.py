"""Trace, lower and compile the Push chunk at its default settings on this machine; one JSON line of seconds."""

import json
import sys
import time

import jax

import envs
from splid_jax.config import TrainConfig
from splid_jax.learners import registry

cfg = TrainConfig(env="push", run_dir="/tmp/unused")
algo = registry.make_algorithm(cfg, envs.make(cfg.env))
like = jax.eval_shape(algo.init, jax.random.PRNGKey(0))
t0 = time.perf_counter()
traced = jax.jit(algo.chunk).trace(like, algo.hyper())
t1 = time.perf_counter()
lowered = traced.lower()
t2 = time.perf_counter()
lowered.compile()
t3 = time.perf_counter()
seconds = {"trace_s": round(t1 - t0, 1), "lower_s": round(t2 - t1, 1), "compile_s": round(t3 - t2, 1)}
print(json.dumps({"tag": sys.argv[1] if len(sys.argv) > 1 else "", **seconds}))
