"""The command line: its one-line errors (exit code 2), and a run's policy and the scripted Push from
the same starts in both simulators."""

import builtins
import json
import sys

import jax
import mujoco
import numpy as np
import pytest

pytest.importorskip("gymnasium_robotics")

from envs import make as make_env  # noqa: E402
from envs.fetch import scripted  # noqa: E402
from splid_jax.config import TrainConfig  # noqa: E402
from splid_jax.learners.registry import make_algorithm  # noqa: E402
from splid_jax.reference import cli, episodes, mapping, policy  # noqa: E402
from splid_jax.reference import side as reference_side  # noqa: E402
from splid_jax.runtime import checkpoint  # noqa: E402
from splid_jax.runtime.run_files import env_settings  # noqa: E402


def _init_run(run_dir, env_name: str, **fields):
    """A run directory holding the untrained state of a small run: config.json and checkpoint 0."""
    cfg = TrainConfig(env=env_name, iterations=1, eval_every=1, num_envs=2, horizon=2, hidden=(8,), buffer_size=16,
                      batch_size=4, run_dir=str(run_dir), **fields)  # fmt: skip
    env = cfg.make_env()
    checkpoint.save(run_dir, 0, make_algorithm(cfg, env).init(jax.random.PRNGKey(0)), {"env": env_settings(env)})
    (run_dir / "config.json").write_text(json.dumps(cfg.to_json()))
    return run_dir


def _error(capsys, argv) -> str:
    assert cli.main(argv) == 2
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
    assert "RUN_DIR" in _error(capsys, [str(tmp_path), "--reference"])  # no config.json
    assert "is not a directory" in _error(capsys, [str(tmp_path / "absent"), "--reference"])
    cfg = TrainConfig(env="reach", run_dir=str(tmp_path))
    (tmp_path / "config.json").write_text(json.dumps(cfg.to_json()))
    assert "no checkpoint" in _error(capsys, [str(tmp_path), "--reference"])


def test_checkpoint_without_policy_is_one_line(tmp_path, capsys, monkeypatch):
    import splid_jax.rollout

    run = _init_run(tmp_path / "run", "reach")
    monkeypatch.setattr(splid_jax.rollout, "load_policy", lambda cfg, step: (None, None, object(), 0))
    assert "holds no policy" in _error(capsys, [str(run), "--reference"])


def test_traces_in_a_missing_directory_is_one_line_before_any_episode(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(cli, "scripted", lambda *a: pytest.fail("evaluated before the flags were checked"))
    traces = str(tmp_path / "no" / "t.npz")
    argv = ["--scripted", "reach", "--reference", "--out", str(tmp_path / "r.json"), "--traces", traces]
    assert "--traces" in _error(capsys, argv)


def test_result_written_when_its_directory_was_moved_away_meanwhile(tmp_path, capsys, monkeypatch):
    out = tmp_path / "results" / "r.json"
    out.parent.mkdir()
    side = {"episodes": 1, "success_any": 1.0, "success_any_ci95": [0.2, 1.0], "success_final": 1.0,
            "success_final_ci95": [0.2, 1.0], "median_final_distance": 0.01}  # fmt: skip

    def evaluated_while_moved(*args):
        out.parent.rename(tmp_path / "elsewhere")
        return {"reference": "FetchReach-v4", "ours": side, "fetch": side}, {}

    monkeypatch.setattr(cli, "scripted", evaluated_while_moved)
    assert cli.main(["--scripted", "reach", "--reference", "--episodes", "1", "--out", str(out)]) == 0
    assert json.loads(out.read_text())["fetch"]["success_final"] == 1.0


def test_reference_flag_is_required(tmp_path, capsys):
    assert "--reference" in _error(capsys, [str(tmp_path)])


@pytest.mark.slow
def test_evaluator_on_reach_writes_both_simulators_numbers_and_traces(tmp_path, capsys):
    run = _init_run(tmp_path / "run", "reach")
    assert cli.main([str(run), "--reference", "--episodes", "3", "--traces", str(tmp_path / "t.npz")]) == 0
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
    # the reference side alone (what another interpreter runs) gives the same numbers
    alone_argv = [str(run), "--episodes", "3", "--seed", "0", "--step", "0", "--out", str(tmp_path / "s")]
    assert reference_side.main(alone_argv) == 0
    alone = json.loads((tmp_path / "s").read_text())
    assert alone["fetch"] == got["fetch"] and alone["versions"] == got["versions"]
    # and the evaluator takes it from the interpreter it is given, with this run's settings
    fake = tmp_path / "python"
    fake.write_text(f"#!/bin/sh\necho \"$@\" > {tmp_path / 'argv'}\n"
                    f"cp {tmp_path / 's'} \"$(echo \"$@\" | sed 's/.*--out \\([^ ]*\\).*/\\1/')\"\n")  # fmt: skip
    fake.chmod(0o755)
    argv = [str(run), "--reference", "--episodes", "3", "--out", str(tmp_path / "o")]
    assert cli.main([*argv, "--reference-python", str(fake)]) == 0
    other = json.loads((tmp_path / "o").read_text())
    assert other["fetch"] == got["fetch"] and other["ours"] == got["ours"] and other["versions"] == got["versions"]
    called = (tmp_path / "argv").read_text().split()
    assert called[:2] == ["-m", "splid_jax.reference.side"] and called[2] == str(run)
    assert called[called.index("--step") + 1] == "0" and called[called.index("--episodes") + 1] == "3"
    # traced there: our starts go to that interpreter as a file and its episodes from them come back as one
    env = policy.load_run(str(run))[1]
    mapping.save_starts(tmp_path / "starts.npz", mapping.our_starts(env, jax.random.PRNGKey(0), 3))
    there = ["--starts", str(tmp_path / "starts.npz"), "--traces", str(tmp_path / "side.npz")]
    assert reference_side.main([*alone_argv, *there]) == 0
    fake.write_text(f"#!{sys.executable}\nimport shutil, sys\na = sys.argv\n"
                    f"shutil.copy(a[a.index('--starts') + 1], {str(tmp_path / 'sent.npz')!r})\n"
                    f"shutil.copy({str(tmp_path / 'side.npz')!r}, a[a.index('--traces') + 1])\n"
                    f"shutil.copy({str(tmp_path / 's')!r}, a[a.index('--out') + 1])\n")  # fmt: skip
    traced = [*argv, "--overwrite", "--reference-python", str(fake), "--traces", str(tmp_path / "t2.npz")]
    assert cli.main(traced) == 0
    sent = mapping.load_starts(tmp_path / "sent.npz")
    np.testing.assert_array_equal(sent["goal"], mapping.load_starts(tmp_path / "starts.npz")["goal"])
    here, elsewhere = np.load(tmp_path / "t.npz"), np.load(tmp_path / "t2.npz")
    assert set(here.files) == set(elsewhere.files) and "fetch_actions" in here.files
    for key in here.files:  # the same starts, episodes and traces as when the reference ran in this process
        np.testing.assert_array_equal(here[key], elsewhere[key], err_msg=key)


def test_a_reference_interpreter_that_cannot_run_is_one_line(tmp_path, capsys):
    run = tmp_path / "run"
    run.mkdir()
    err = _error(capsys, [str(run), "--reference", "--reference-python", str(tmp_path / "nowhere")])
    assert "--reference-python" in err and "not an executable file" in err
    err = _error(capsys, ["--scripted", "reach", "--reference", "--reference-python", sys.executable])
    assert "--reference-python" in err and "--scripted" in err


@pytest.mark.slow
def test_evaluator_on_push_and_the_scripted_push_in_both_simulators(tmp_path, capsys):
    # the library's Cholesky, the same physics to float rounding, compiles Push's episodes faster than the unrolled one
    run = _init_run(tmp_path / "run", "push", env_options="cholesky=library")
    assert cli.main([str(run), "--reference", "--episodes", "2", "--out", str(tmp_path / "r.json")]) == 0
    got = json.loads((tmp_path / "r.json").read_text())
    assert got["reference"] == "FetchPush-v4" and got["fetch"]["episodes"] == 2
    assert got["versions"]["mujoco"] == mujoco.__version__ and got["versions"]["gymnasium_robotics"] == "1.4.2"
    assert "note:" not in capsys.readouterr().out  # the release notice is Slide's alone
    # the mapping: the scripted controller, fed each simulator's raw observation, pushes the cube home in both
    env = make_env("push", cholesky="library")
    act = jax.jit(scripted.push)
    ours, ref = episodes.matched_episodes(env, "push", scripted.push, act, 2, 0)
    np.testing.assert_allclose(ours.obs[:, 0, :9], ref.obs[:, 0, :9], atol=2e-3)  # same start, same layout
    np.testing.assert_allclose(ours.goal, ref.goal, atol=2e-3)
    assert ours.success[:, -1].all() and ref.success[:, -1].all()


def test_an_earlier_result_is_kept_unless_overwrite_is_given(tmp_path, capsys, monkeypatch):
    side = {"episodes": 1, "success_any": 1.0, "success_any_ci95": [0.2, 1.0], "success_final": 1.0,
            "success_final_ci95": [0.2, 1.0], "median_final_distance": 0.01}  # fmt: skip
    monkeypatch.setattr(cli, "scripted", lambda *a: ({"reference": "FetchReach-v4", "ours": side, "fetch": side}, {}))
    out = tmp_path / "r.json"
    out.write_text("earlier")
    argv = ["--scripted", "reach", "--reference", "--episodes", "1", "--out", str(out)]
    assert f"--out {out}: already exists (pass --overwrite" in _error(capsys, argv)
    assert out.read_text() == "earlier"
    assert cli.main([*argv, "--overwrite"]) == 0 and json.loads(out.read_text())["fetch"]["episodes"] == 1


@pytest.mark.parametrize(
    "argv, said",
    [
        (["--seed", "-1"], "--seed -1: must be an integer in [0, 2**32)"),
        (["--eval-subgoal-reach", "-1"], "invalid --eval-subgoal-reach -1.0: must be a distance >= 0"),
        (["--scripted", "pushh"], "argument --scripted: invalid choice: 'pushh'"),
    ],
)
def test_a_bad_flag_is_one_line_naming_it(tmp_path, capsys, argv, said):
    run = _init_run(tmp_path / "run", "reach")
    if argv[0] == "--scripted":
        run_args = ["--reference", *argv]
        with pytest.raises(SystemExit) as stop:
            cli.main(run_args)
        err = capsys.readouterr().err.strip()
        assert stop.value.code == 2 and err.count("\n") == 0 and said in err, err
        return
    assert said in _error(capsys, [str(run), "--reference", "--episodes", "1", *argv])
    assert not (run / "reference.json").exists()


def test_an_out_in_a_directory_without_write_permission_is_one_line_before_any_episode(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(cli, "scripted", lambda *a: pytest.fail("evaluated before --out was checked"))
    monkeypatch.setattr(cli, "unwritable", lambda d: "Permission denied" if d == str(tmp_path) else None)
    argv = ["--scripted", "reach", "--reference", "--out", str(tmp_path / "r.json")]
    said = f"--out {tmp_path / 'r.json'}: its directory cannot be written in (Permission denied)"
    assert said in _error(capsys, argv)
