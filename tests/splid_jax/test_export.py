"""Exporting a run's policy without its buffer: the same policy loads from the export, which is small
and cannot be resumed."""

import json

import jax
import numpy as np
import pytest

from envs import make as make_env
from splid_jax import export, train
from splid_jax.config import TrainConfig
from splid_jax.learners.registry import make_algorithm
from splid_jax.reference.policy import restore_run
from splid_jax.runtime import checkpoint
from splid_jax.runtime.run_files import env_settings


def _saved_run(run_dir, **fields):
    """A run directory of train's layout whose checkpoint at step 3 holds a freshly built state."""
    cfg = TrainConfig(env="reach", iterations=3, eval_every=1, num_envs=2, run_dir=str(run_dir), **fields)
    env = make_env(cfg.env)
    state = make_algorithm(cfg, env).init(jax.random.PRNGKey(7))
    checkpoint.save(run_dir, 3, state, {"env": env_settings(env)})
    (run_dir / "config.json").write_text(json.dumps(cfg.to_json()))
    (run_dir / "metrics.jsonl").write_text(json.dumps({"iteration": 3, "eval_success": 0.5}) + "\n")
    return state


def _same_policy(a, b):
    for x, y in zip(jax.tree.leaves(a), jax.tree.leaves(b), strict=True):
        np.testing.assert_array_equal(np.asarray(x), np.asarray(y))


def test_an_export_holds_the_runs_policy_and_a_one_slot_buffer(tmp_path, capsys):
    run = tmp_path / "run"
    state = _saved_run(run, hidden=(8,), buffer_size=4096, batch_size=4)
    assert export.main([str(run), "--out", str(tmp_path / "out")]) == 0
    assert "(iteration 3)" in capsys.readouterr().out
    cfg, _, _, loaded, step = restore_run(str(tmp_path / "out" / "run"))
    assert step == 3 and cfg.buffer_size == 1 and loaded.buffer.obs.shape[0] == 1
    _same_policy(loaded.policy, state.policy)
    record = json.loads((tmp_path / "out" / "run" / "export.json").read_text())
    assert record["run_dir"] == str(run) and record["step"] == 3 and record["config"]["buffer_size"] == 4096
    assert (tmp_path / "out" / "run" / "metrics.jsonl").read_text() == (run / "metrics.jsonl").read_text()


def test_her_exports_with_one_episode_of_replay_and_its_other_options_kept(tmp_path):
    run = tmp_path / "her"
    state = _saved_run(run, algo="her", her_options="hidden=8,8,buffer_transitions=500,update_every=0,n_batches=2")
    assert export.main([str(run), "--out", str(tmp_path / "out")]) == 0
    cfg, env, algo, loaded, _ = restore_run(str(tmp_path / "out" / "her"))
    her = cfg.learner_config()
    assert (her.buffer_transitions, her.hidden, her.n_batches) == (env.episode_length, (8, 8), 2)
    _same_policy(loaded.policy, state.policy)


def test_an_export_is_refused_over_an_existing_directory_and_for_resume(tmp_path, capsys):
    run = tmp_path / "run"
    _saved_run(run, hidden=(8,), buffer_size=64, batch_size=4)
    (tmp_path / "out" / "run").mkdir(parents=True)
    assert export.main([str(run), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "invalid --out " in err and "does not exist yet" in err
    assert export.main([str(run), "--out", str(tmp_path / "new")]) == 0
    assert train.main(["--resume", str(tmp_path / "new" / "run"), "--iterations", "6"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.splitlines()[-1].endswith("(its export.json names the run)")


def _another_export_wins(out):
    real = checkpoint.save

    def save(run_dir, *a, **kw):
        (out / "run").mkdir(parents=True)  # the other export's rename lands first
        (out / "run" / "config.json").write_text("{}")
        return real(run_dir, *a, **kw)

    return save


def _disk_full(*a, **kw):
    raise ValueError("RESOURCE_EXHAUSTED: Failed writing: No space left on device [os_error_code='28']")


@pytest.mark.parametrize(
    "save, code, said",
    [(_another_export_wins, 2, "another export wrote it meanwhile"), (lambda out: _disk_full, 3, "no space left")],
    ids=["two-exports", "full-disk"],
)
def test_a_failed_export_is_one_line_and_leaves_nothing_half_written(tmp_path, capsys, monkeypatch, save, code, said):
    run, out = tmp_path / "run", tmp_path / "out"
    _saved_run(run, hidden=(8,), buffer_size=64, batch_size=4)
    monkeypatch.setattr(checkpoint, "save", save(out))
    assert export.main([str(run), "--out", str(out)]) == code
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and said in err
    assert sorted(p.name for p in out.iterdir()) == (["run"] if code == 2 else [])  # no temporary left
    monkeypatch.undo()
    if code == 3:  # the retry is not refused by what the failed one left
        assert export.main([str(run), "--out", str(out)]) == 0


@pytest.mark.parametrize("out", ["", "bad-\udcff"], ids=["empty", "not-utf8"])
def test_an_empty_or_undecodable_out_is_refused(tmp_path, capsys, monkeypatch, out):
    monkeypatch.chdir(tmp_path)
    assert export.main([str(tmp_path / "run"), "--out", out]) == 2
    assert f"invalid --out {out!r}" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("under", ["", "sub"], ids=["a-file", "under-a-file"])
def test_an_out_that_is_a_file_is_one_line_before_any_run_is_read(tmp_path, capsys, under):
    (tmp_path / "taken").write_text("kept")
    out = tmp_path / "taken" / under if under else tmp_path / "taken"
    assert export.main([str(tmp_path / "no-run"), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and f"invalid --out {out}: must be a directory" in err
    assert (tmp_path / "taken").read_text() == "kept"
