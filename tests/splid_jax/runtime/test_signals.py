"""A checkpoint save is not cut short by a first signal, and never waited for past a second one or
its grace: a save stuck on a filesystem cannot hold the process."""

import signal
import subprocess
import sys
import threading

import pytest

from splid_jax.runtime import checkpoint
from splid_jax.runtime.signals import SaveAbandoned, Signals


def save_until(release: threading.Event, *signals_to_send, by: Signals):
    """A save that sends ``signals_to_send`` to ``by`` as it starts, then waits for ``release`` (at most 30 s)."""

    def save():
        for signum in signals_to_send:
            by._caught(signum, None)
        release.wait(30)
        return "saved"

    return save


def test_a_save_without_a_signal_returns_its_result():
    s = Signals()
    assert s.finish(lambda: "saved", grace=0.0) == "saved"


def test_a_first_signal_lets_the_save_finish():
    s, release = Signals(), threading.Event()
    threading.Timer(0.2, release.set).start()
    assert s.finish(save_until(release, signal.SIGTERM, by=s), grace=float("inf")) == "saved"
    assert s.signum == signal.SIGTERM


def test_a_second_signal_abandons_the_save():
    s, release = Signals(), threading.Event()
    with pytest.raises(SaveAbandoned) as stop:
        s.finish(save_until(release, signal.SIGTERM, signal.SIGTERM, by=s), grace=float("inf"))
    release.set()
    assert stop.value.exit_code == 143


def test_a_save_past_its_grace_is_abandoned():
    s, release = Signals(), threading.Event()
    with pytest.raises(SaveAbandoned):
        s.finish(save_until(release, signal.SIGINT, by=s), grace=0.1)
    release.set()


def test_work_begun_runs_beside_the_caller_and_hands_back_its_result_or_error():
    s, release = Signals(), threading.Event()
    began = s.begin(lambda: release.wait(30) and "built")
    release.set()  # only a thread already running can see it: begin returned without waiting
    assert s.wait(began) == "built"
    with pytest.raises(ValueError, match="no state"):
        s.wait(s.begin(lambda: (_ for _ in ()).throw(ValueError("no state"))))


HANGS_AT_10 = """
import runpy, sys, threading
from splid_jax.runtime import checkpoint
real = checkpoint.save
def save(run_dir, step, *a, **kw):
    if step == 10:
        print("saving 10", flush=True)
        threading.Event().wait()
    return real(run_dir, step, *a, **kw)
checkpoint.save = save
sys.argv = ["train", *sys.argv[1:]]
runpy.run_module("splid_jax.train", run_name="__main__", alter_sys=True)
"""


def test_two_signals_end_a_run_whose_save_hangs_keeping_the_last_whole_checkpoint(tmp_path):
    run_dir = str(tmp_path / "run")
    args = ["--env", "point", "--num-envs", "8", "--eval-episodes", "16", "--bc-steps", "5", "--batch-size", "16",
            "--hidden", "16", "--eval-every", "5", "--iterations", "20", "--checkpoint-every", "1"]  # fmt: skip
    proc = subprocess.Popen([sys.executable, "-c", HANGS_AT_10, *args, "--run-dir", run_dir],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)  # fmt: skip
    try:
        for line in proc.stdout:
            if line.startswith("saving 10"):
                break
        proc.send_signal(signal.SIGTERM)
        threading.Event().wait(0.5)  # two signals in one instant may reach Python as one
        proc.send_signal(signal.SIGTERM)
        out, err = proc.communicate(timeout=120)
    finally:
        proc.kill()
    assert proc.returncode == 143 and "Traceback" not in err, err
    assert "while saving iteration 10, not waited for: the last whole checkpoint, iteration 5 is kept" in out
    assert checkpoint.latest_step(run_dir) == 5


def test_a_wait_past_its_lateness_reports_once_and_still_returns_the_result():
    reported, late = [], threading.Event()

    def on_late(seconds):
        reported.append(seconds)
        late.set()

    s = Signals()
    assert s.wait(lambda: (late.wait(30), "done")[1], late_after=0.0, on_late=on_late) == "done"
    assert len(reported) == 1 and reported[0] >= 0.0


def test_a_wait_within_its_lateness_reports_nothing():
    reported = []
    assert Signals().wait(lambda: "done", late_after=3600.0, on_late=reported.append) == "done"
    assert reported == []
