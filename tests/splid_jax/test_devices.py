"""Splitting a sweep's members or a run's envs across devices, on two host-platform CPU devices.

XLA_FLAGS must be set before JAX starts, so each check runs in a fresh interpreter."""

import json
import os
import subprocess
import sys
import textwrap

import pytest

from envs.base import InvalidConfig
from splid_jax import devices

TWO = {**os.environ, "XLA_FLAGS": "--xla_force_host_platform_device_count=2 " + os.environ.get("XLA_FLAGS", "")}


def run_two_devices(code: str, tmp_path) -> dict:
    script = tmp_path / "two_devices.py"
    script.write_text(textwrap.dedent(code))
    out = subprocess.run([sys.executable, str(script)], env=TWO, capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr[-3000:]
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_a_run_split_by_envs_computes_the_one_device_iteration_exactly(tmp_path):
    got = run_two_devices(
        """
        import json, jax, numpy as np, envs
        from splid_jax import devices
        from splid_jax.config import TrainConfig
        from splid_jax.trainer import Trainer
        env = envs.make("point")
        out = {}
        for algo in ("splid", "gcsl"):
            cfg = TrainConfig(env="point", algo=algo, num_envs=8, buffer_size=2000, hidden=(16, 16), bc_steps=5,
                              batch_size=32, run_dir="unused")
            one = Trainer(env, cfg)
            two = Trainer(env, cfg, devices.place(2, cfg.num_envs, devices.ENVS).mesh)
            ts = one.init(jax.random.PRNGKey(3))
            a, ma = jax.jit(one.iteration)(ts, one.hyper())
            b, mb = jax.jit(two.iteration)(ts, two.hyper())
            same = jax.tree.map(lambda x, y: bool(np.array_equal(np.asarray(x), np.asarray(y))), (a, ma), (b, mb))
            out[algo] = [all(jax.tree.leaves(same)), int(ma["select_accepted"])]
        print(json.dumps(out))
        """,
        tmp_path,
    )
    assert got["splid"][0] and got["gcsl"][0]
    assert got["splid"][1] > 0  # SELECT kept pairs: the gathered candidates were compared, not empty ones


def test_a_sweep_split_by_members_computes_each_group_as_one_device_and_resumes_bit_for_bit(tmp_path):
    got = run_two_devices(
        f"""
        import json, os, dataclasses
        from splid_jax import loop
        from splid_jax.config import TrainConfig
        def sweep(run_dir, iterations, resume=False, members=4, num_devices=2):
            cfg = TrainConfig(env="point", num_envs=8, buffer_size=2000, hidden=(16, 16), bc_steps=5, batch_size=32,
                              eval_every=2, eval_episodes=20, iterations=iterations, run_dir=run_dir,
                              num_devices=num_devices)
            lanes = [dataclasses.replace(cfg, seed=s, run_dir=os.path.join(run_dir, f"s{{s}}")) for s in range(members)]
            loop.run(cfg, members=lanes, resume=resume, quiet=True)
        root = {str(tmp_path)!r}
        sweep(root + "/straight", 4)
        sweep(root + "/stopped", 2)
        sweep(root + "/stopped", 4, resume=True)
        sweep(root + "/one-device", 4, members=2, num_devices=1)  # the first device's group alone
        read = lambda d, m: [json.loads(l) for l in open(os.path.join(root, d, m, "metrics.jsonl"))]
        drop = lambda rs: [{{k: v for k, v in r.items() if k not in ("wall_s", "steps_per_s")}} for r in rs]
        devices = json.load(open(os.path.join(root, "straight", "s0", "config.json")))["devices"]
        print(json.dumps({{
            "resumed": all(drop(read("straight", m)) == drop(read("stopped", m)) for m in ("s0", "s3")),
            "as_one_device": all(drop(read("straight", m)) == drop(read("one-device", m)) for m in ("s0", "s1")),
            "rows": len(read("stopped", "s3")), "devices": devices}}))
        """,
        tmp_path,
    )
    assert got["resumed"] and got["as_one_device"] and got["rows"] == 2
    assert got["devices"] == {"kind": "cpu", "count": 2, "processes": 1}


def test_the_device_count_must_divide_what_it_splits():
    with pytest.raises(InvalidConfig, match="num_devices"):
        devices.place(5, 8, devices.MEMBERS)  # more than this process sees
    assert devices.place(0, 7, devices.ENVS).count == 1
    assert devices.place(1, 8, devices.MEMBERS).record()["count"] == 1
