"""Splitting a sweep's members or a run's envs across devices, on two host-platform CPU devices.

XLA_FLAGS must be set before JAX starts, so the checks run once, in a fresh interpreter."""

import json
import os
import subprocess
import sys
import textwrap

import pytest

from splid_jax.common.errors import InvalidConfig
from splid_jax.runtime import devices

SCRIPT = """
import dataclasses, json, os, sys
import jax, numpy as np, envs
from splid_jax.runtime import devices, loop
from splid_jax.config import TrainConfig
from splid_jax.learners.splid.trainer import Trainer
root = sys.argv[1]
small = dict(env="point", num_envs=8, buffer_size=2000, hidden=(16, 16), bc_steps=5, batch_size=32, run_dir="unused")
out = {}

# one iteration of a run whose envs are split, against the one-device iteration
env = envs.make("point")
for algo in ("splid", "gcsl"):
    cfg = TrainConfig(**small, algo=algo)
    one, two = Trainer(env, cfg), Trainer(env, cfg, devices.place(2, cfg.num_envs, devices.ENVS).mesh)
    ts = one.init(jax.random.PRNGKey(3))
    a, b = jax.jit(one.iteration)(ts, one.hyper()), jax.jit(two.iteration)(ts, two.hyper())
    # counts and flags alike, floats to rounding: XLA:CPU may vectorise 8 envs and 2 x 4 apart
    close = lambda x, y: bool(np.allclose(x, y, rtol=1e-5, atol=1e-6) if np.issubdtype(x.dtype, np.floating)
                              else np.array_equal(x, y))
    same = jax.tree.map(lambda x, y: close(np.asarray(x), np.asarray(y)), a, b)
    out[algo] = [all(jax.tree.leaves(same)), int(a[1]["select_accepted"])]

# a sweep whose members are split: against one device, and resumed after a stop
def sweep(name, iterations, resume=False, members=4, num_devices=2):
    run_dir = os.path.join(root, name)
    cfg = TrainConfig(**{**small, "run_dir": run_dir}, eval_every=2, eval_episodes=20, iterations=iterations,
                      num_devices=num_devices)
    lanes = [dataclasses.replace(cfg, seed=s, run_dir=os.path.join(run_dir, f"s{s}")) for s in range(members)]
    loop.run(cfg, members=lanes, resume=resume, quiet=True)

sweep("straight", 4)
sweep("stopped", 2)
sweep("stopped", 4, resume=True)
sweep("one-device", 4, members=2, num_devices=1)  # the first device's group alone
read = lambda d, m: [json.loads(l) for l in open(os.path.join(root, d, m, "metrics.jsonl"))]
drop = lambda rs: [{k: v for k, v in r.items() if k not in ("wall_s", "steps_per_s")} for r in rs]
out["resumed"] = all(drop(read("straight", m)) == drop(read("stopped", m)) for m in ("s0", "s3"))
out["as_one_device"] = all(drop(read("straight", m)) == drop(read("one-device", m)) for m in ("s0", "s1"))
out["rows"] = len(read("stopped", "s3"))
out["devices"] = [json.load(open(os.path.join(root, "straight", m, "config.json")))["devices"] for m in ("s0", "s3")]
print(json.dumps(out))
"""


@pytest.fixture(scope="module")
def two_devices(tmp_path_factory) -> dict:
    root = tmp_path_factory.mktemp("two_devices")
    (root / "script.py").write_text(textwrap.dedent(SCRIPT))
    # the suite's faster-compiling flags too: the split run is held to rounding, the sweeps to their own programs
    flags = "--xla_force_host_platform_device_count=2 " + os.environ.get("XLA_FLAGS", "")
    run = subprocess.run(
        [sys.executable, str(root / "script.py"), str(root)],
        env={**os.environ, "XLA_FLAGS": flags},
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert run.returncode == 0, run.stderr[-3000:]
    return json.loads(run.stdout.strip().splitlines()[-1])


def test_a_run_split_by_envs_computes_the_one_device_iteration_to_rounding(two_devices):
    assert two_devices["splid"][0] and two_devices["gcsl"][0]
    assert two_devices["splid"][1] > 0  # SELECT kept pairs: real candidates were gathered and compared


def test_a_sweep_split_by_members_computes_each_group_as_one_device_does(two_devices):
    assert two_devices["as_one_device"]
    placed = {"kind": "cpu", "count": 2, "processes": 1, "ids": [0, 1]}
    assert two_devices["devices"] == [{**placed, "member_on": 0}, {**placed, "member_on": 1}]


def test_a_split_sweep_resumes_bit_for_bit(two_devices):
    assert two_devices["resumed"] and two_devices["rows"] == 2


def test_the_device_count_must_divide_what_it_splits():
    with pytest.raises(InvalidConfig, match="num_devices"):
        devices.place(5, 8, devices.MEMBERS)  # more than this process sees
    assert devices.place(0, 7, devices.ENVS).count == 1
    assert devices.place(1, 8, devices.MEMBERS).record()["count"] == 1
