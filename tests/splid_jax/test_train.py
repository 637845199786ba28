"""The command line and its run directory: bad input, resume after a real kill, Ctrl-C, NaN,
corrupt and mismatched checkpoints. All on the point task, in subprocesses where a signal is real."""

import json
import os
import signal
import subprocess
import sys
import time

import jax
import numpy as np
import pytest

from splid_jax import checkpoint
from splid_jax.config import TrainConfig
from splid_jax.train import RunStopped, _interrupt_after, main, run
from splid_jax.trainer import Trainer

TINY = ["--env", "point", "--num-envs", "8", "--eval-episodes", "16", "--bc-steps", "40", "--batch-size", "64",
        "--hidden", "32,32", "--eval-every", "5"]  # fmt: skip
VOLATILE = {"wall_s", "steps_per_s"}


# A shell starts background jobs with SIGINT ignored, and a child inherits that: the Ctrl-C test would
# then test nothing when pytest itself runs in the background. This prelude gives the run the Ctrl-C
# handling it has when started from a terminal.
AT_A_TERMINAL = (
    "import runpy, signal; signal.signal(signal.SIGINT, signal.default_int_handler); "
    "runpy.run_module('splid_jax.train', run_name='__main__', alter_sys=True)"
)


def cli(*args, **kw):
    return subprocess.Popen(
        [sys.executable, "-c", AT_A_TERMINAL, *args],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        **kw,
    )


def stable(path):
    with open(os.path.join(path, "metrics.jsonl")) as fh:
        return [{k: v for k, v in json.loads(line).items() if k not in VOLATILE} for line in fh]


def final_params(run_dir):
    cfg = TrainConfig(**{**json.load(open(os.path.join(run_dir, "config.json"))), "hidden": (32, 32)})
    trainer = Trainer(__import__("envs").make("point"), cfg)
    _, state, _ = checkpoint.restore(run_dir, trainer.init(jax.random.PRNGKey(0)))
    return jax.tree_util.tree_leaves(state)


@pytest.mark.parametrize(
    "args,field",
    [
        (["--sigma", "-1"], "sigma"),
        (["--horizon", "0"], "horizon"),
        (["--horizon", "50"], "horizon"),
        (["--num-envs", "0"], "num_envs"),
        (["--policy-ema", "1"], "policy_ema"),
        (["--env", "nope"], "env"),
        (["--iterations", "7", "--eval-every", "5"], "iterations"),
        (["--env-options", "success_radius"], "env_options"),
        (["--env-options", "bogus=1"], "point.bogus"),
        (["--env-options", "max_episode_steps=8"], "horizon"),  # H = 8 must stay below the episode length
    ],
)
def test_bad_values_stop_before_any_work(tmp_path, capsys, args, field):
    run_dir = tmp_path / "run"
    assert main(["--run-dir", str(run_dir), *args]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and field in err
    assert not run_dir.exists()


def test_run_dir_that_is_a_file_is_refused(tmp_path, capsys):
    f = tmp_path / "file"
    f.write_text("x")
    assert main(["--run-dir", str(f)]) == 2
    assert "run_dir" in capsys.readouterr().err


def test_help_documents_every_flag(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["--help"])
    assert exc.value.code == 0
    out = capsys.readouterr().out
    for flag in ["--env", "--seed", "--iterations", "--num-envs", "--sigma", "--horizon", "--no-select", "--run-dir",
                 "--resume"]:  # fmt: skip
        assert flag in out


@pytest.mark.slow
def test_resume_after_kill_matches_an_uninterrupted_run(tmp_path):
    whole, killed = str(tmp_path / "whole"), str(tmp_path / "killed")
    args = [*TINY, "--iterations", "60", "--policy-ema", "0.9", "--quiet"]  # the averaged policy is state too
    reference = cli(*args, "--run-dir", whole)
    victim = cli(*args, "--run-dir", killed)
    deadline = time.time() + 240
    while (checkpoint.latest_step(killed) or 0) < 10 and victim.poll() is None and time.time() < deadline:
        time.sleep(0.02)
    victim.send_signal(signal.SIGKILL)
    victim.wait()
    assert victim.returncode == -signal.SIGKILL, "the run ended before it could be killed"
    killed_at = checkpoint.latest_step(killed)
    assert 10 <= killed_at < 60
    assert reference.wait() == 0, reference.stderr.read()
    resumed = cli("--resume", killed, "--quiet")
    assert resumed.wait() == 0, resumed.stderr.read()
    assert checkpoint.latest_step(killed) == 60
    assert stable(killed) == stable(whole)
    for a, b in zip(final_params(killed), final_params(whole), strict=True):
        np.testing.assert_array_equal(a, b)


def test_a_rerun_compiles_nothing_new_and_repeats_the_run(tmp_path):
    cache = str(tmp_path / "cache")
    args = [*TINY, "--iterations", "10", "--quiet", "--checkpoint-every", "0", "--compile-cache", cache]
    env = {**os.environ, "JAX_PERSISTENT_CACHE_MIN_COMPILE_TIME_SECS": "0"}  # keep even fast compiles
    first = cli(*args, "--run-dir", str(tmp_path / "first"), env=env)
    assert first.wait() == 0, first.stderr.read()
    kept = sorted(os.listdir(cache))
    assert any("chunk" in name for name in kept)
    again = cli(*args, "--run-dir", str(tmp_path / "again"), env=env)
    assert again.wait() == 0, again.stderr.read()
    assert sorted(os.listdir(cache)) == kept  # every program came from the cache
    assert stable(str(tmp_path / "again")) == stable(str(tmp_path / "first"))


@pytest.mark.slow
def test_ctrl_c_saves_and_exits_cleanly(tmp_path):
    run_dir = str(tmp_path / "run")
    proc = cli(*TINY, "--iterations", "1000", "--run-dir", run_dir)
    deadline = time.time() + 240
    while (checkpoint.latest_step(run_dir) or 0) < 5 and proc.poll() is None and time.time() < deadline:
        time.sleep(0.02)
    proc.send_signal(signal.SIGINT)
    out, _ = proc.communicate(timeout=120)
    assert proc.returncode == 130
    step = checkpoint.latest_step(run_dir)
    assert "interrupted: saved iteration" in out and f"iteration {step} " in out
    # the checkpoint holds the last finished chunk; metrics may be one chunk ahead, dropped on resume
    assert step >= 5 and step <= stable(run_dir)[-1]["iteration"] <= step + 5


@pytest.mark.slow
def test_nan_stops_the_run_and_keeps_the_last_good_checkpoint(tmp_path):
    cfg = TrainConfig(env="point", num_envs=8, eval_episodes=16, bc_steps=5, batch_size=32, hidden=(16,),
                      eval_every=5, iterations=20, learning_rate=1e38, run_dir=str(tmp_path / "run"))  # fmt: skip
    with pytest.raises(RunStopped, match="non-finite"):
        run(cfg, quiet=True)
    step = checkpoint.latest_step(cfg.run_dir)
    assert step is not None and step < 20
    trainer = Trainer(__import__("envs").make("point"), cfg)
    _, state, _ = checkpoint.restore(cfg.run_dir, trainer.init(jax.random.PRNGKey(0)))
    assert all(np.isfinite(np.asarray(x)).all() for x in jax.tree_util.tree_leaves(state.policy.params))


@pytest.mark.slow
def test_corrupt_and_mismatched_checkpoints_fail_clearly(tmp_path, capsys):
    run_dir = tmp_path / "run"
    assert main([*TINY, "--iterations", "5", "--run-dir", str(run_dir), "--quiet"]) == 0
    assert main(["--resume", str(run_dir), "--hidden", "8"]) == 2  # a changed network is not this run
    assert "hidden" in capsys.readouterr().err
    cfg = json.loads((run_dir / "config.json").read_text())
    (run_dir / "config.json").write_text(json.dumps({**cfg, "hidden": [8]}))
    assert main(["--resume", str(run_dir), "--iterations", "10", "--quiet"]) == 3
    assert "hidden" in capsys.readouterr().err
    (run_dir / "config.json").write_text(json.dumps(cfg))
    for root, _, files in os.walk(run_dir / "checkpoints"):
        for name in files:
            path = os.path.join(root, name)
            if os.path.getsize(path) > 64:
                with open(path, "r+b") as fh:
                    fh.truncate(os.path.getsize(path) // 2)
    assert main(["--resume", str(run_dir), "--iterations", "10", "--quiet"]) == 3
    assert "error" in capsys.readouterr().err


def test_env_options_build_the_task_the_run_trains_on(tmp_path):
    run_dir = tmp_path / "run"
    args = ["--run-dir", str(run_dir), "--iterations", "5", "--num-envs", "4", "--bc-steps", "2"]
    args += ["--eval-episodes", "4"]
    assert main([*args, "--env-options", "max_episode_steps=20,success_radius=0.5", "--quiet"]) == 0
    cfg = json.load(open(run_dir / "config.json"))
    assert cfg["env_options"] == "max_episode_steps=20,success_radius=0.5"
    rec = json.loads(open(run_dir / "metrics.jsonl").readline())
    assert rec["env_steps"] == 5 * 4 * 20  # episodes of the overridden length


def test_ctrl_c_during_a_checkpoint_write_waits_for_the_write(tmp_path):
    state = {"w": np.arange(4.0)}
    with pytest.raises(KeyboardInterrupt):
        with _interrupt_after():
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(0.05)  # the signal is handled in here, and held
            checkpoint.save(str(tmp_path), 5, state, {"config": {}})
    assert checkpoint.latest_step(str(tmp_path)) == 5  # written whole, then the interrupt came
    _, restored, _ = checkpoint.restore(str(tmp_path), state)
    np.testing.assert_array_equal(restored["w"], state["w"])


def test_resume_under_changed_task_defaults_fails_naming_the_option(tmp_path):
    # the same config both times; only the task itself differs, as after a change of its defaults
    import envs
    from splid_jax.checkpoint import CheckpointError

    cfg = TrainConfig(env="point", num_envs=4, eval_episodes=4, bc_steps=2, batch_size=16, hidden=(8,),
                      eval_every=5, iterations=5, run_dir=str(tmp_path / "run"))  # fmt: skip
    run(cfg, env=envs.make("point"), quiet=True)
    longer = TrainConfig(**{**cfg.__dict__, "iterations": 10})
    with pytest.raises(CheckpointError, match=r"env\.door_half_width=0\.75 but env\.door_half_width=0\.5"):
        run(longer, env=envs.make("point", door_half_width=0.5), resume=True, quiet=True)
    assert run(longer, env=envs.make("point"), resume=True, quiet=True)["iteration"] == 10
