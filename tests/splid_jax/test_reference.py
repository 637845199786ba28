"""The evaluator in the reference simulator (Gymnasium-Robotics Fetch*-v4): the run-time fix, the
statistics, the error cases, and a run's policy and the scripted Push from the same starts in both."""

import builtins
import importlib.util
import json

import jax
import numpy as np
import pytest

pytest.importorskip("gymnasium_robotics")

from envs.fetch import scripted  # noqa: E402
from splid_jax import reference  # noqa: E402
from splid_jax.config import TrainConfig  # noqa: E402
from splid_jax.learners.registry import make_algorithm  # noqa: E402
from splid_jax.runtime import checkpoint  # noqa: E402
from splid_jax.runtime.loop import make_env  # noqa: E402
from splid_jax.runtime.run_files import env_settings  # noqa: E402


def fresh_mujoco_utils():
    """An unpatched copy of gymnasium-robotics' ``utils/mujoco_utils.py``."""
    import gymnasium_robotics.utils.mujoco_utils as mu

    spec = importlib.util.spec_from_file_location("mujoco_utils_copy", mu.__file__)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_fix_is_applied_only_where_the_getters_fail():
    import mujoco

    mu = fresh_mujoco_utils()
    fails = reference.joint_getters_fail(mu)
    newer = tuple(int(x) for x in mujoco.__version__.split(".")[:2]) >= (3, 12)
    assert fails == newer
    assert reference.fix_joint_type_asserts(mu) == fails
    assert not reference.joint_getters_fail(mu)
    assert reference.fix_joint_type_asserts(mu) is False  # applied once


def test_fixed_getters_read_and_write_each_joint_type():
    import mujoco

    xml = """<mujoco><worldbody>
      <body><joint name="f" type="free"/><geom size="0.1"/></body>
      <body><joint name="b" type="ball"/><geom size="0.1"/></body>
      <body><joint name="s" type="slide"/><joint name="h" type="hinge"/><geom size="0.1"/></body>
    </worldbody></mujoco>"""
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    mu = fresh_mujoco_utils()
    reference.fix_joint_type_asserts(mu)
    for name, nq, nv in (("f", 7, 6), ("b", 4, 3), ("s", 1, 1), ("h", 1, 1)):
        mu.set_joint_qpos(m, d, name, np.arange(nq) + 1.0)
        mu.set_joint_qvel(m, d, name, np.arange(nv) + 2.0)
        np.testing.assert_array_equal(mu.get_joint_qpos(m, d, name), np.arange(nq) + 1.0)
        np.testing.assert_array_equal(mu.get_joint_qvel(m, d, name), np.arange(nv) + 2.0)


def test_fetch_push_resets_and_steps_with_the_fix():
    env = reference.make_reference("push")
    obs, _ = env.reset(seed=0)
    assert obs["observation"].shape == (25,) and obs["desired_goal"].shape == (3,)
    obs, *_ = env.step(np.zeros(4))
    env.close()


def test_wilson_interval():
    lo, hi = reference.wilson(0, 10)
    assert lo == 0.0 and hi == pytest.approx(0.2775, abs=1e-4)
    lo, hi = reference.wilson(10, 10)
    assert hi == 1.0 and lo == pytest.approx(0.7225, abs=1e-4)
    lo, hi = reference.wilson(210, 300)  # p = 0.7
    assert lo == pytest.approx(0.6463, abs=1e-3) and hi == pytest.approx(0.7487, abs=1e-3)


def test_summarise():
    s = reference.summarise([1, 1, 0, 1], [1, 0, 0, 1], [0.01, 0.1, 0.2, 0.03])
    assert s["episodes"] == 4 and s["success_any"] == 0.75 and s["success_final"] == 0.5
    assert s["median_final_distance"] == pytest.approx(0.065)
    assert s["success_final_ci95"][0] < 0.5 < s["success_final_ci95"][1]


def _init_run(run_dir, env_name: str, **fields):
    """A run directory holding the untrained state of a small run: config.json and checkpoint 0."""
    cfg = TrainConfig(env=env_name, iterations=1, eval_every=1, num_envs=2, horizon=2, hidden=(8,), buffer_size=16,
                      batch_size=4, run_dir=str(run_dir), **fields)  # fmt: skip
    env = make_env(cfg.env, **cfg.env_overrides())
    checkpoint.save(run_dir, 0, make_algorithm(cfg, env).init(jax.random.PRNGKey(0)), {"env": env_settings(env)})
    (run_dir / "config.json").write_text(json.dumps(cfg.to_json()))
    return run_dir


def _error(capsys, argv) -> str:
    assert reference.main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "Traceback" not in err
    return err


def test_missing_extra_is_one_line(tmp_path, capsys, monkeypatch):
    real = builtins.__import__

    def no_gym(name, *a, **k):
        if name.split(".")[0] in ("gymnasium", "gymnasium_robotics"):
            raise ImportError(name)
        return real(name, *a, **k)

    monkeypatch.setattr(builtins, "__import__", no_gym)
    assert 'pip install -e ".[reference]"' in _error(capsys, [str(tmp_path), "--reference"])


def test_task_without_reference_is_one_line(tmp_path, capsys):
    cfg = TrainConfig(env="point", run_dir=str(tmp_path))
    (tmp_path / "config.json").write_text(json.dumps(cfg.to_json()))
    assert "no reference simulator" in _error(capsys, [str(tmp_path), "--reference"])


def test_directory_without_run_or_checkpoint_is_one_line(tmp_path, capsys):
    assert "run_dir" in _error(capsys, [str(tmp_path), "--reference"])  # no config.json
    assert "is not a directory" in _error(capsys, [str(tmp_path / "absent"), "--reference"])
    cfg = TrainConfig(env="reach", run_dir=str(tmp_path))
    (tmp_path / "config.json").write_text(json.dumps(cfg.to_json()))
    assert "no checkpoint" in _error(capsys, [str(tmp_path), "--reference"])


def test_checkpoint_without_policy_is_one_line(tmp_path, capsys, monkeypatch):
    import splid_jax.rollout

    run = _init_run(tmp_path / "run", "reach")
    monkeypatch.setattr(splid_jax.rollout, "load_policy", lambda cfg, step: (None, None, object(), 0))
    assert "holds no policy" in _error(capsys, [str(run), "--reference"])


def test_reference_flag_is_required(tmp_path, capsys):
    assert "--reference" in _error(capsys, [str(tmp_path)])


@pytest.mark.slow
def test_evaluator_on_reach_writes_both_simulators_numbers_and_traces(tmp_path, capsys):
    run = _init_run(tmp_path / "run", "reach")
    assert reference.main([str(run), "--reference", "--episodes", "3", "--traces", str(tmp_path / "t.npz")]) == 0
    out = capsys.readouterr().out
    assert "FetchReach-v4" in out and "ours (MJX)" in out
    got = json.loads((run / "reference.json").read_text())
    for side in ("ours", "fetch"):
        assert got[side]["episodes"] == 3
        assert 0 <= got[side]["success_final"] <= got[side]["success_any"] <= 1
        lo, hi = got[side]["success_any_ci95"]
        assert lo <= got[side]["success_any"] <= hi
    tr = np.load(tmp_path / "t.npz")
    assert tr["ours_distance"].shape == tr["fetch_distance"].shape == (3, 51)
    np.testing.assert_allclose(tr["ours_distance"][:, 0], tr["fetch_distance"][:, 0], atol=2e-3)  # same starts
    assert tr["ours_obs"].shape == tr["fetch_obs"].shape == (3, 51, 10)
    assert set(got["slots"]) >= {"grip x", "finger vel r"}
    assert tr["response_fetch_step"].shape == tr["response_ours_rest_step"].shape == (20, 3)


@pytest.mark.slow
def test_evaluator_on_push_and_the_scripted_push_in_both_simulators(tmp_path, capsys):
    run = _init_run(tmp_path / "run", "push")
    assert reference.main([str(run), "--reference", "--episodes", "2", "--out", str(tmp_path / "r.json")]) == 0
    got = json.loads((tmp_path / "r.json").read_text())
    assert got["reference"] == "FetchPush-v4" and got["fetch"]["episodes"] == 2
    # the mapping: the scripted controller, fed each simulator's raw observation, pushes the cube home in both
    env = make_env("push")
    act = jax.jit(scripted.push)
    ours, ref = reference.matched_episodes(env, "push", scripted.push, act, 2, 0)
    np.testing.assert_allclose(ours.obs[:, 0, :9], ref.obs[:, 0, :9], atol=2e-3)  # same start, same layout
    np.testing.assert_allclose(ours.goal, ref.goal, atol=2e-3)
    assert ours.success[:, -1].all() and ref.success[:, -1].all()


def test_a_sweep_member_loads_its_slice_of_the_sweep_checkpoint(tmp_path):
    sweep = tmp_path / "sweep"
    cfg = TrainConfig(env="reach", iterations=1, eval_every=1, num_envs=2, horizon=2, hidden=(8,), buffer_size=16,
                      batch_size=4, run_dir=str(sweep))  # fmt: skip
    env = make_env(cfg.env)
    stacked = jax.vmap(make_algorithm(cfg, env).init)(jax.random.split(jax.random.PRNGKey(0), 2))
    checkpoint.save(sweep, 3, stacked, {"env": env_settings(env)})
    names = ["m0", "m1"]
    for name in names:
        (sweep / name).mkdir()
        (sweep / name / "config.json").write_text(json.dumps({**cfg.to_json(), "run_dir": str(sweep / name)}))
    members = [{**cfg.to_json(), "run_dir": n} for n in names]
    (sweep / "sweep.json").write_text(json.dumps({"config": cfg.to_json(), "members": members}))
    _, _, _, pstate, step = reference.load_run(str(sweep / "m1"))
    assert step == 3
    want = jax.tree.leaves(jax.tree.map(lambda x: x[1], stacked.policy.params))
    for got, exp in zip(jax.tree.leaves(pstate.params), want, strict=True):
        np.testing.assert_array_equal(np.asarray(got), np.asarray(exp))


def test_compare_slots_names_each_slot():
    ours = np.zeros((2, 3, 25))
    fetch = ours.copy()
    fetch[:, :, 13] = 0.5  # the object's yaw
    got = reference.compare_slots(ours, fetch)
    assert list(got)[13] == "euler c" and len(got) == 25
    assert got["euler c"] == {"ours": 0.0, "fetch": 0.5, "diff": 0.5, "start_diff": 0.5}
    assert got["grip x"]["diff"] == 0.0


@pytest.mark.slow
def test_response_measurements_move_the_gripper_and_the_cube_in_both_simulators():
    env = make_env("push")
    resp = reference.step_response(env, "push", hold=2, release=1)
    assert np.asarray(resp["ours_step"]).shape == np.asarray(resp["fetch_rest_step"]).shape == (3, 3)
    assert resp["ours_step"][1][0] > 0.02 and resp["fetch_step"][1][0] > 0.02  # a_x = 1: tens of mm per step
    slide = reference.cube_slide(env, "push", (0.5, 0.0), steps=3)
    assert slide["ours_travel"] > 0.005 and slide["fetch_travel"] > 0.005
    push = reference.loaded_push(env, "push", (0.0, 1.0, 0.0, 0.0), hold=3, release=1)
    assert sum(push["ours_object_step"]) > 0.02 and sum(push["fetch_object_step"]) > 0.02
