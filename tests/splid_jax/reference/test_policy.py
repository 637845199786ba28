"""Loading a run's policy: a sweep member's slice of the sweep's stacked checkpoint."""

import json

import jax
import numpy as np
import pytest

pytest.importorskip("gymnasium_robotics")

from envs import make as make_env  # noqa: E402
from splid_jax.config import TrainConfig  # noqa: E402
from splid_jax.learners.registry import make_algorithm  # noqa: E402
from splid_jax.reference import policy  # noqa: E402
from splid_jax.runtime import checkpoint  # noqa: E402
from splid_jax.runtime.run_files import env_settings  # noqa: E402


def _sweep(tmp_path, trained_env=None):
    """A two-member sweep directory with one stacked checkpoint at step 3; ``trained_env``: the task the
    checkpoint records (default: the config's)."""
    sweep = tmp_path / "sweep"
    cfg = TrainConfig(env="reach", iterations=1, eval_every=1, num_envs=2, horizon=2, hidden=(8,), buffer_size=16,
                      batch_size=4, run_dir=str(sweep))  # fmt: skip
    env = make_env(cfg.env)
    stacked = jax.vmap(make_algorithm(cfg, env).init)(jax.random.split(jax.random.PRNGKey(0), 2))
    checkpoint.save(sweep, 3, stacked, {"env": env_settings(trained_env or env)})
    names = ["m0", "m1"]
    for name in names:
        (sweep / name).mkdir()
        (sweep / name / "config.json").write_text(json.dumps({**cfg.to_json(), "run_dir": str(sweep / name)}))
    members = [{**cfg.to_json(), "run_dir": n} for n in names]
    (sweep / "sweep.json").write_text(json.dumps({"config": cfg.to_json(), "members": members}))
    return sweep, stacked


def test_a_sweep_member_loads_its_slice_of_the_sweep_checkpoint(tmp_path, capsys):
    sweep, stacked = _sweep(tmp_path)
    _, _, _, pstate, step = policy.load_run(str(sweep / "m1"))
    assert "another version of the task" not in capsys.readouterr().err
    assert step == 3
    want = jax.tree.leaves(jax.tree.map(lambda x: x[1], stacked.policy.params))
    for got, exp in zip(jax.tree.leaves(pstate.params), want, strict=True):
        np.testing.assert_array_equal(np.asarray(got), np.asarray(exp))


def test_a_sweep_member_trained_on_another_version_of_the_task_says_so(tmp_path, capsys):
    sweep, _ = _sweep(tmp_path, trained_env=make_env("reach", finger_table=1.0))
    policy.load_run(str(sweep / "m0"))
    assert "another version of the task (finger_table=1.0 then, 0.0 now)" in capsys.readouterr().err
    # an option recorded only when set (gripper_mass) is named both ways: set then, and set now only
    later = _sweep(tmp_path / "later", trained_env=make_env("reach", gripper_mass=5.0))[0]
    policy.load_run(str(later / "m0"))
    assert "another version of the task (gripper_mass=5.0 then, 0.0 now)" in capsys.readouterr().err
    policy.load_run(str(sweep / "m0"), env_options="gripper_mass=5")
    assert "gripper_mass=0.0 then, 5.0 now" in capsys.readouterr().err
