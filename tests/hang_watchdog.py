"""A test that runs past ``SPLID_JAX_TEST_TIMEOUT`` seconds (default 240) is taken to hang: every
thread's stack and the test's id go to the hang log, and its process exits, so the run goes on
instead of waiting forever.

Why: XLA:CPU (jaxlib 0.10) now and then never finishes a computation: the caller waits while every XLA
thread is idle (about one run in 25 of a small vmapped sweep; experiments/NOTES.md, "A computation that
never finishes on the CPU"). A Python-level timeout cannot end such a call, and pytest-timeout's own dump is lost
with an xdist worker's stderr; the log keeps it. ``.ci/run`` runs a test that hung once more, and
only when hangs were the run's only failures.

The log is ``SPLID_JAX_HANG_LOG``, else ``.pytest_cache/hung-tests.log`` under the rootdir: lines
``HUNG <node id>`` followed by the stacks. Beside it, ``<log>.retry`` holds the node ids to run again,
written by the controlling process only when every failure of the run was a hang.
"""

from __future__ import annotations

import faulthandler
import os
import signal
import sys
import threading

import pytest

EXIT_CODE = 70
_FAILED: set[str] = set()  # node ids of failed reports, as the controlling process receives them


def _timeout_s() -> float:
    return float(os.environ.get("SPLID_JAX_TEST_TIMEOUT", "240"))


def hang_log(config: pytest.Config) -> str:
    return os.environ.get("SPLID_JAX_HANG_LOG") or os.path.join(str(config.rootpath), ".pytest_cache", "hung-tests.log")


def _hung(path: str, nodeid: str, seconds: float) -> None:
    os.makedirs(os.path.dirname(path) or ".", exist_ok=True)
    with open(path, "a") as f:
        f.write(f"HUNG {nodeid}\n# still running after {seconds:.0f} s; every thread's stack:\n")
        f.flush()
        faulthandler.dump_traceback(file=f, all_threads=True)
    _kill_children()
    print(f"\n{nodeid} still running after {seconds:.0f} s: stacks in {path}", file=sys.__stderr__, flush=True)
    os._exit(EXIT_CODE)


def _kill_children() -> None:
    """SIGKILL this process's children (a test's subprocesses), which would otherwise outlive it."""
    me = str(os.getpid())
    for pid in filter(str.isdigit, os.listdir("/proc") if os.path.isdir("/proc") else []):
        try:
            with open(f"/proc/{pid}/stat") as f:
                parent = f.read().rsplit(")", 1)[1].split()[1]
            if parent == me:
                os.kill(int(pid), signal.SIGKILL)
        except (OSError, IndexError):
            pass


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item: pytest.Item, nextitem):
    seconds = _timeout_s()
    timer = threading.Timer(seconds, _hung, args=(hang_log(item.config), item.nodeid, seconds))
    timer.daemon = True
    timer.start()
    try:
        yield
    finally:
        timer.cancel()


def _is_controller(config: pytest.Config) -> bool:
    return not hasattr(config, "workerinput")


def pytest_configure(config: pytest.Config) -> None:
    if _is_controller(config):
        for path in (hang_log(config), hang_log(config) + ".retry"):
            if os.path.exists(path):
                os.remove(path)


def pytest_runtest_logreport(report: pytest.TestReport) -> None:
    if report.failed:
        _FAILED.add(report.nodeid)


def hung_ids(path: str) -> list[str]:
    if not os.path.exists(path):
        return []
    with open(path) as f:
        return [line.split(" ", 1)[1].strip() for line in f if line.startswith("HUNG ")]


def pytest_sessionfinish(session: pytest.Session, exitstatus: int) -> None:
    config = session.config
    if not _is_controller(config):
        return
    hung = hung_ids(hang_log(config))
    if hung and _FAILED <= set(hung):
        with open(hang_log(config) + ".retry", "w") as f:
            f.write("".join(f"{nodeid}\n" for nodeid in dict.fromkeys(hung)))


def pytest_terminal_summary(terminalreporter, exitstatus: int, config: pytest.Config) -> None:
    hung = hung_ids(hang_log(config)) if _is_controller(config) else []
    if hung:
        terminalreporter.write_line(f"{len(hung)} test(s) hung; node ids and stacks in {hang_log(config)}")
