"""One sweep over two processes (``jax.distributed`` on two local CPU processes, one device each):
process 0 alone writes, a signal to either stops both with a checkpoint, and the members' metrics are
those of the sweep in one process, on an MJX task. Launch options that cannot work are refused with
one line."""

import json
import os
import pickle
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import jax
import pytest

from splid_jax import sweep, train
from splid_jax.common.errors import InvalidConfig
from splid_jax.runtime import devices, multihost

# the smallest Fetch sweep: chunks of two iterations of 4-step episodes, into a buffer of 64 pairs (Reach's own
# million would be the state gathered for each checkpoint and sent to process 1 on resume)
TINY = ["--env", "reach", "--env-options", "max_episode_steps=4", "--num-envs", "2", "--eval-episodes", "2",
        "--eval-every", "2", "--bc-steps", "2", "--batch-size", "8", "--hidden", "8", "--buffer-size", "64",
        "--seeds", "2", "--horizons", "2", "--no-plot"]  # fmt: skip
VOLATILE = {"wall_s", "steps_per_s"}
MEMBERS = ("sigma1-H2-s0", "sigma1-H2-s1")
REPO = Path(__file__).resolve().parents[3]


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def launch(root, tag: str, args_of) -> list[subprocess.Popen]:
    """Processes 0 and 1 of one sweep (``python -m splid_jax.sweep``, both writing the suite's compile cache,
    so the resumed pair compiles nothing); ``args_of(i)`` gives process i's own arguments."""
    port = free_port()
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [str(REPO), os.environ.get("PYTHONPATH")]))}
    procs = []
    for i in range(2):
        out = open(root / f"{tag}-{i}.out", "w")
        cmd = [sys.executable, "-m", "tests.compile_cache", "splid_jax.sweep", *args_of(i),
               "--coordinator", f"127.0.0.1:{port}", "--num-processes", "2", "--process-id", str(i)]  # fmt: skip
        procs.append(subprocess.Popen(cmd, stdout=out, stderr=subprocess.STDOUT, text=True, env=env))
    return procs


def finish(procs, timeout: float = 180) -> list[int]:
    """Exit codes; a process still running after ``timeout`` (a hang) is killed and fails the test."""
    deadline, codes = time.monotonic() + timeout, []
    for p in procs:
        try:
            codes.append(p.wait(timeout=max(deadline - time.monotonic(), 1)))
        except subprocess.TimeoutExpired:
            for q in procs:
                q.kill()
            pytest.fail("a process of the two-process sweep hung")
    return codes


def stable(root, run, member):
    with open(root / run / member / "metrics.jsonl") as fh:
        return [{k: v for k, v in json.loads(line).items() if k not in VOLATILE} for line in fh]


@pytest.fixture(scope="module")
def two_processes(tmp_path_factory) -> dict:
    """A sweep over two processes stopped by SIGTERM to process 1 after process 0 showed a chunk, then
    resumed by two processes, the second with a run directory that does not exist; and the same
    sweep in one process. The task is an MJX one: each process steps the task's model from its own
    device, since on process 0's, process 1 could neither close over it in its programs nor read it."""
    root = tmp_path_factory.mktemp("two_processes")
    run_dirs = [str(root / "p0"), str(root / "p1")]
    first = launch(root, "first", lambda i: [*TINY, "--iterations", "1000", "--run-dir", run_dirs[i]])
    deadline = time.monotonic() + 180
    while "iter " not in (root / "first-0.out").read_text() and first[0].poll() is None:
        assert time.monotonic() < deadline, "no chunk within 180 s"
        time.sleep(0.05)
    first[1].send_signal(signal.SIGTERM)
    stopped = finish(first)
    step = max(int(s) for s in os.listdir(root / "p0" / "checkpoints"))
    resumed = finish(launch(root, "resumed", lambda i: ["--resume", run_dirs[i], "--iterations", str(step + 2)]))
    assert sweep.main([*TINY, "--quiet", "--iterations", str(step + 2), "--run-dir", str(root / "one")]) == 0
    return {"root": root, "stopped": stopped, "resumed": resumed, "step": step}


def test_a_signal_to_one_process_stops_both_with_a_checkpoint_and_the_sweep_resumes(two_processes):
    assert two_processes["stopped"] == [143, 143], (two_processes["root"] / "first-0.out").read_text()[-3000:]
    assert two_processes["resumed"] == [0, 0], (two_processes["root"] / "resumed-0.out").read_text()[-3000:]
    rows = stable(two_processes["root"], "p0", MEMBERS[0])
    assert [r["iteration"] for r in rows][-2:] == [two_processes["step"], two_processes["step"] + 2]


def test_only_process_0_writes_and_each_member_computes_as_in_one_process(two_processes):
    root = two_processes["root"]
    assert not (root / "p1").exists()
    assert sorted(os.listdir(root / "p0")) == sorted(["checkpoints", "grid.png", "sweep.json", *MEMBERS])
    for member in MEMBERS:
        assert stable(root, "p0", member) == stable(root, "one", member)
    config = json.loads((root / "p0" / MEMBERS[1] / "config.json").read_text())
    placed = config["devices"]
    assert {k: placed[k] for k in ("kind", "count", "processes")} == {"kind": "cpu", "count": 2, "processes": 2}
    assert len(set(placed["ids"])) == 2 and placed["member_on"] == placed["ids"][1]  # process 1's device
    for i in range(2):  # no traceback, and process 1 shows nothing
        out = (root / f"resumed-{i}.out").read_text()
        assert "Traceback" not in out and ("iter " in out) == (i == 0)


@pytest.mark.parametrize("main", [sweep.main, train.main])
@pytest.mark.parametrize(
    "args, field, flag",
    [
        (["--num-processes", "0"], "num_processes", "--num-processes"),
        (["--num-processes", "2", "--coordinator", "127.0.0.1:1234"], "process_id", "--process-id"),
        (["--num-processes", "2", "--process-id", "2", "--coordinator", "h:1"], "process_id", "--process-id"),
        (["--process-id", "1"], "process_id", "--process-id"),
        (["--num-processes", "2", "--process-id", "0"], "coordinator", "--coordinator"),
        (["--num-processes", "2", "--process-id", "0", "--coordinator", "h"], "coordinator", "--coordinator"),
        (["--num-processes", "2", "--process-id", "0", "--coordinator", "h:99999"], "coordinator", "--coordinator"),
    ],
)
def test_a_bad_launch_is_one_line_naming_the_flag(capsys, tmp_path, main, args, field, flag):
    assert main(["--env", "point", *args, "--run-dir", str(tmp_path / "x")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and f"invalid {flag} " in err
    assert not (tmp_path / "x").exists()


def test_process_0_refuses_a_coordinator_port_in_use(capsys, tmp_path):
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        where = f"127.0.0.1:{taken.getsockname()[1]}"
        args = ["--env", "point", "--num-processes", "2", "--process-id", "0", "--coordinator", where]
        assert sweep.main([*args, "--run-dir", str(tmp_path / "x")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and f"invalid --coordinator {where}:" in err and "in use" in err


def meet_all(port: int, ids, within: float = 10.0) -> tuple[list, list]:
    """``multihost.meet`` for each of ``ids`` of a 3-process run, each in its own thread: what each
    raised (its line) or None, in the order of ``ids``; and the lines shown while waiting."""
    out, shown = [None] * len(ids), []

    def one(k):
        try:
            multihost.meet(multihost.Launch(f"127.0.0.1:{port}", 3, ids[k]), within, shown.append)
        except InvalidConfig as err:
            out[k] = str(err)

    threads = [threading.Thread(target=one, args=(k,)) for k in range(len(ids))]
    for t in threads:
        t.start()
        time.sleep(0.1)  # process 0 first or last alike: the others retry
    for t in threads:
        t.join(timeout=30)
    return out, shown


def test_the_processes_meet_at_process_0_before_jax_joins_them():
    assert meet_all(free_port(), [1, 0, 2]) == ([None, None, None], [])


def test_a_process_that_never_comes_or_a_taken_index_is_one_line_not_a_crash(monkeypatch):
    monkeypatch.setattr(multihost, "_NOTE_AFTER_S", 0.3)
    port = free_port()
    (first, second), shown = meet_all(port, [0, 1], within=1.0)  # process 2 never starts
    assert first == (f"invalid coordinator='127.0.0.1:{port}': must be HOST:PORT that every process reaches "
                     "(process 2 did not within 1 s)")  # fmt: skip
    assert second.endswith("(process 0 stopped waiting for the others)")
    assert "waiting up to 1 s for the others" in shown[0]
    assert "none answered within 0.5 s" in meet_all(free_port(), [2], within=0.5)[0][0]  # no process 0
    twice, _ = meet_all(free_port(), [0, 1, 1, 2])
    assert twice[:2] == [None, None] and twice[3] is None
    assert twice[2].startswith("invalid process_id=1: must be an integer in [0, 3) that no other process of the run")


def test_one_process_needs_no_launch_and_its_errors_travel_whole():
    assert multihost.launch(None, None, None) is None and multihost.launch("h:1", 1, 0) is None
    assert multihost.launch("[::1]:80", 2, 1) == multihost.Launch("[::1]:80", 2, 1)
    with pytest.raises(InvalidConfig, match="^invalid resume='nowhere': must be a sweep directory") as caught:
        multihost._result(multihost._outcome(lambda: sweep.resume_configs("nowhere", {})))
    assert (caught.value.field, caught.value.value) == ("resume", "nowhere")
    assert multihost._result(multihost._outcome(lambda: {"a": jax.numpy.ones(2)}))["a"].tolist() == [1.0, 1.0]
    assert pickle.loads(multihost._outcome(lambda: 3)) == (True, 3)


def test_a_single_run_or_an_unequal_share_is_refused_over_several_processes(monkeypatch):
    monkeypatch.setattr(jax, "process_count", lambda: 2)
    with pytest.raises(InvalidConfig, match="invalid num_processes=2: must be 1 for a single run"):
        devices.place(1, 8, devices.ENVS)
    with pytest.raises(InvalidConfig, match="invalid num_processes=2: must be a divisor of the 3 sweep members"):
        devices.place(1, 3, devices.MEMBERS)
