"""A figure's methods side by side: one child process each, the parent alone writing figure.json, a failed
child named with its log, and a signal passed on once to every child (the training itself: test_figures.py)."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import threading
import time

import pytest

from splid_jax.figures import side_by_side, spreading
from splid_jax.runtime import loop

# a stand-in child: notes that it started, then exits with its method's code, or on SIGTERM notes the signal
CHILD = """
import os, signal, sys, time
out, method = sys.argv[1], sys.argv[2]
def stop(signum, frame):
    open(os.path.join(out, method + ".signals"), "a").write(str(signum) + "\\n")
    sys.exit(128 + signum)
signal.signal(signal.SIGTERM, stop)
print("training", method, flush=True)
open(os.path.join(out, method + ".started"), "w").write(os.environ.get("CUDA_VISIBLE_DEVICES", ""))
code = 3 if method == "bad" else None if method.startswith("slow") else 0
if code is None:
    time.sleep(60)
sys.exit(code)
"""


def record_of(methods, seeds=1):
    members = [{"run_dir": f"s{i}"} for i in range(seeds)]
    runs = {m: {"config": {"iterations": 10}, "members": members} for m in methods}
    return {"figure": "fig3", "methods": list(methods), "runs": runs}


@pytest.fixture
def stand_in(monkeypatch):
    def command(out, method, resume, cache, part=None):
        return [sys.executable, "-c", CHILD, out, method + (f"-{part}" if part else "")]

    monkeypatch.setattr(side_by_side, "child_command", command)


def test_a_failed_method_is_named_with_its_log_and_the_others_seconds_are_kept(tmp_path, stand_in):
    out = str(tmp_path)
    record = record_of(["ok", "bad"])
    with pytest.raises(loop.RunStopped, match=r"1 of 2 methods failed: bad \(exit 3, .*bad\.log\)"):
        side_by_side.train_side_by_side(out, record, quiet=True, resume=False)
    written = json.loads((tmp_path / "figure.json").read_text())  # only the parent writes it
    assert set(written["runs"]) == {"ok", "bad"} and all(r["total_s"] >= 0 for r in written["runs"].values())
    assert (tmp_path / "logs" / "ok.log").read_text() == "training ok\n"


def test_a_signal_is_passed_on_once_to_every_child_and_stops_the_figure(tmp_path, stand_in):
    out = str(tmp_path)
    record = record_of(["slow1", "slow2"])
    default = signal.getsignal(signal.SIGTERM)

    def send_when_ready():  # once the parent passes signals on and both children listen for them
        deadline = time.monotonic() + 30
        started = [os.path.join(out, f"slow{i}.started") for i in (1, 2)]
        while time.monotonic() < deadline:
            if signal.getsignal(signal.SIGTERM) is not default and all(map(os.path.exists, started)):
                os.kill(os.getpid(), signal.SIGTERM)
                return
            time.sleep(0.05)

    sender = threading.Thread(target=send_when_ready)
    sender.start()
    with pytest.raises(loop.Interrupted) as stopped:
        side_by_side.train_side_by_side(out, record, quiet=True, resume=False)
    sender.join()
    assert stopped.value.exit_code == 143
    for child in ("slow1", "slow2"):
        assert (tmp_path / f"{child}.signals").read_text() == f"{int(signal.SIGTERM)}\n"
    assert signal.getsignal(signal.SIGTERM) is default  # the parent's handlers are restored


def test_children_get_the_compile_cache_the_resume_and_the_gpu_shared(tmp_path, monkeypatch):
    cmd = side_by_side.child_command("OUT", "her", True, "/cache")
    assert cmd[1:] == ["-m", "splid_jax.figures.side_by_side", "OUT", "her", "--compile-cache", "/cache", "--resume"]
    monkeypatch.setenv("CUDA_MPS_PIPE_DIRECTORY", str(tmp_path))
    assert not side_by_side.mps_running()
    (tmp_path / "control").touch()
    assert side_by_side.mps_running()


def test_a_child_asked_for_a_method_the_figure_lacks_is_one_line(tmp_path, capsys):
    (tmp_path / "figure.json").write_text(json.dumps(record_of(["gcsl"])))
    assert side_by_side.main([str(tmp_path), "her"]) == 2
    assert capsys.readouterr().err.strip().endswith(f"no method 'her' in {tmp_path}")


def test_a_child_whose_parent_is_gone_stops_itself(tmp_path):
    # a parent killed outright cannot pass a signal on: its children then stop as if it had sent SIGTERM
    marker = tmp_path / "stopped"
    child = (
        "import signal, sys, time\n"
        "from splid_jax.figures.side_by_side import stop_when_orphaned\n"
        f"signal.signal(signal.SIGTERM, lambda *a: (open({str(marker)!r}, 'w').write('15'), sys.exit(143)))\n"
        "import os; stop_when_orphaned(os.getppid(), every_s=0.05)\n"
        "print('watching', flush=True)\n"
        "time.sleep(30)\n"
    )
    parent = (  # starts the child, waits until it watches, then exits without a word to it
        "import subprocess, sys\n"
        f"p = subprocess.Popen([sys.executable, '-c', {child!r}], stdout=subprocess.PIPE, start_new_session=True)\n"
        "p.stdout.readline()\n"
    )
    subprocess.run([sys.executable, "-c", parent], check=True, timeout=60)
    deadline = time.monotonic() + 20
    while not marker.exists() and time.monotonic() < deadline:
        time.sleep(0.05)
    assert marker.read_text() == "15"


def test_children_are_spread_over_the_gpus_and_the_record_names_each_ones(tmp_path, stand_in, monkeypatch):
    monkeypatch.setattr(spreading, "visible_gpus", lambda: ["3", "5"])
    out = str(tmp_path)
    side_by_side.train_side_by_side(out, record_of(["es", "her"], seeds=2), quiet=True, resume=False)
    written = json.loads((tmp_path / "figure.json").read_text())
    # three GPUs would split her; two hold the two methods, heaviest (her) first on the first
    assert {m: ran["gpu"] for m, ran in written["runs"].items()} == {"her": "3", "es": "5"}
    assert (tmp_path / "her.started").read_text() == "3" and (tmp_path / "es.started").read_text() == "5"


def test_a_method_split_by_seed_runs_one_child_per_part(tmp_path, stand_in, monkeypatch):
    monkeypatch.setattr(spreading, "visible_gpus", lambda: ["0", "1", "2"])
    out = str(tmp_path)
    side_by_side.train_side_by_side(out, record_of(["es", "her"], seeds=2), quiet=True, resume=False)
    parts = json.loads((tmp_path / "figure.json").read_text())["runs"]["her"]["parts"]
    assert [(p["dir"], p["gpu"]) for p in parts] == [("seeds-0-0", "0"), ("seeds-1-1", "1")]
    assert (tmp_path / "her-seeds-1-1.started").read_text() == "1"
    assert (tmp_path / "logs" / "her-seeds-0-0.log").exists()


def test_a_child_asked_for_a_part_the_method_lacks_is_one_line(tmp_path, capsys):
    split = spreading.split(record_of(["her"], seeds=2), 2)
    (tmp_path / "figure.json").write_text(json.dumps(split))
    assert side_by_side.main([str(tmp_path), "her", "--part", "seeds-0-1"]) == 2
    assert capsys.readouterr().err.strip().endswith(f"no method 'her' part 'seeds-0-1' in {tmp_path}")


@pytest.mark.parametrize("code, at_once", [(143, True), (130, True), (0, False), (3, False)])
def test_an_interrupted_child_ends_at_once_not_through_pythons_shutdown(monkeypatch, code, at_once):
    ended = []

    def exit_now(status):
        ended.append(status)
        raise SystemExit(status)

    monkeypatch.setattr(side_by_side, "main", lambda argv=None: code)
    monkeypatch.setattr(os, "_exit", exit_now)
    monkeypatch.setattr(signal, "signal", lambda sig, handler: None)  # this process's handlers stay as they are
    with pytest.raises(SystemExit) as stop:
        side_by_side.run([])
    assert stop.value.code == code
    assert ended == ([code] if at_once else [])
