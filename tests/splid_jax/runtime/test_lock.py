"""One process per run directory: a second is refused in one line before it writes anything, and a
lock left by a killed process is taken over."""

import os
import signal
import subprocess
import sys

import pytest

from splid_jax import figures, sweep, train
from splid_jax.common.errors import InvalidConfig
from splid_jax.runtime import lock

HOLD = (
    "import sys, time; from splid_jax.runtime import lock; lock.acquire(sys.argv[1]); "
    "print('held', flush=True); time.sleep(600)"
)


@pytest.fixture
def holder(tmp_path):
    """A real process holding the lock of tmp_path/run until the test kills it."""
    run_dir = tmp_path / "run"
    proc = subprocess.Popen([sys.executable, "-c", HOLD, str(run_dir)], stdout=subprocess.PIPE, text=True)
    assert proc.stdout.readline().strip() == "held"
    yield proc, run_dir
    if proc.poll() is None:
        proc.kill()
        proc.wait()


@pytest.mark.parametrize(
    "command,args",
    [
        (train.main, ["--env", "point", "--iterations", "5", "--eval-every", "5", "--run-dir"]),
        (sweep.main, ["--env", "point", "--iterations", "5", "--eval-every", "5", "--seeds", "1", "--run-dir"]),
        (figures.main, ["fig3", "--quick", "--seeds", "1", "--out"]),
    ],
)
def test_a_second_process_is_refused_before_writing(holder, capsys, command, args):
    proc, run_dir = holder
    assert command([*args, str(run_dir)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and f"process {proc.pid} holds it" in err
    assert os.listdir(run_dir) == [lock.LOCK]


def test_a_killed_holders_lock_is_taken_over(holder):
    proc, run_dir = holder
    with pytest.raises(InvalidConfig, match="no other run"):
        lock.acquire(str(run_dir))
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    fd, made = lock.acquire(str(run_dir))
    assert open(run_dir / lock.LOCK).read().strip() == str(os.getpid())
    lock.release(str(run_dir), fd, made)
    assert os.listdir(run_dir) == []


def test_a_lock_on_a_new_directory_leaves_nothing_behind(tmp_path):
    with lock.hold(str(tmp_path / "a" / "b")):
        assert os.listdir(tmp_path / "a" / "b") == [lock.LOCK]
    assert os.listdir(tmp_path) == []


def test_a_resume_of_a_run_in_use_names_resume(holder, capsys):
    import json

    from splid_jax.config import TrainConfig

    proc, run_dir = holder
    config = json.dumps(TrainConfig(env="point", iterations=5, eval_every=5, run_dir=str(run_dir)).to_json())
    (run_dir / "config.json").write_text(config)
    assert train.main(["--resume", str(run_dir), "--iterations", "10"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and f"invalid --resume {run_dir}: " in err and f"process {proc.pid}" in err
    assert sorted(os.listdir(run_dir)) == sorted([lock.LOCK, "config.json"])
    assert (run_dir / "config.json").read_text() == config
