"""The command line as a real process, where a signal is real: killed and resumed, Ctrl-C and SIGTERM at any
moment, and a rerun that compiles nothing new. All on the point task."""

import json
import os
import signal
import subprocess
import sys
import time

import jax
import numpy as np
import pytest

from splid_jax.config import TrainConfig
from splid_jax.learners.splid.trainer import Trainer
from splid_jax.runtime import checkpoint
from splid_jax.train import main

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
    cfg = TrainConfig.from_json(json.load(open(os.path.join(run_dir, "config.json"))), hidden=(32, 32))
    trainer = Trainer(__import__("envs").make("point"), cfg)
    _, state, _ = checkpoint.restore(run_dir, trainer.init(jax.random.PRNGKey(0)))
    return jax.tree_util.tree_leaves(state)


@pytest.mark.slow
def test_resume_after_kill_matches_an_uninterrupted_run(tmp_path):
    whole, killed = str(tmp_path / "whole"), str(tmp_path / "killed")
    args = [*TINY, "--iterations", "30", "--policy-ema", "0.9", "--quiet"]  # the averaged policy is state too
    victim = cli(*args, "--run-dir", killed)  # a real process, really killed; the rest runs in this one
    deadline = time.time() + 240
    while (checkpoint.latest_step(killed) or 0) < 10 and victim.poll() is None and time.time() < deadline:
        time.sleep(0.02)
    victim.send_signal(signal.SIGKILL)
    victim.wait()
    assert victim.returncode == -signal.SIGKILL, "the run ended before it could be killed"
    killed_at = checkpoint.latest_step(killed)
    assert 10 <= killed_at < 30
    assert main([*args, "--run-dir", whole]) == 0
    assert main(["--resume", killed, "--quiet"]) == 0
    assert checkpoint.latest_step(killed) == 30
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
    assert all(any(part in name for name in kept) for part in ("trained", "report"))  # the chunk's two programs
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
    out, err = proc.communicate(timeout=120)
    assert proc.returncode == 130 and "Traceback" not in err
    step = checkpoint.latest_step(run_dir)
    assert "interrupted (SIGINT): saved iteration" in out and f"iteration {step} " in out
    # the checkpoint holds the last finished chunk; metrics may be one chunk ahead, dropped on resume
    assert step >= 5 and step <= stable(run_dir)[-1]["iteration"] <= step + 5


def wait_for(proc, text):
    """Reads the run's stdout up to the first line holding ``text``."""
    for line in proc.stdout:
        if text in line:
            return
    raise AssertionError(f"the run ended before printing {text!r}: {proc.stderr.read()}")


@pytest.mark.slow
@pytest.mark.parametrize("sig, code", [(signal.SIGINT, 130), (signal.SIGTERM, 143)], ids=["SIGINT", "SIGTERM"])
def test_a_signal_during_the_first_compilation_exits_cleanly(tmp_path, sig, code):
    run_dir = str(tmp_path / "run")
    proc = cli(*TINY, "--iterations", "10", "--run-dir", run_dir, "--compile-cache", "")
    wait_for(proc, "compiling")
    proc.send_signal(sig)
    out, err = proc.communicate(timeout=120)
    assert proc.returncode == code, err
    assert "Traceback" not in err and "interrupted" in out and "nothing saved" in out
    assert checkpoint.latest_step(run_dir) is None


def test_a_signal_within_the_first_second_exits_cleanly(tmp_path):
    proc = cli(*TINY, "--run-dir", str(tmp_path / "run"))
    time.sleep(0.5)  # JAX is still loading
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130 and "Traceback" not in err and "interrupted" in err
    assert not (tmp_path / "run").exists()


@pytest.mark.slow
def test_sigterm_saves_like_ctrl_c_and_the_run_resumes(tmp_path):
    run_dir = str(tmp_path / "run")
    proc = cli(*TINY, "--iterations", "1000", "--checkpoint-every", "0", "--run-dir", run_dir)
    wait_for(proc, " 10/1000")
    proc.send_signal(signal.SIGTERM)
    out, err = proc.communicate(timeout=120)
    assert proc.returncode == 143 and "Traceback" not in err
    step = checkpoint.latest_step(run_dir)
    assert step >= 10 and f"saved iteration {step} " in out
    assert main(["--resume", run_dir, "--iterations", str(step + 5), "--quiet"]) == 0
    assert [r["iteration"] for r in stable(run_dir)] == list(range(5, step + 10, 5))
