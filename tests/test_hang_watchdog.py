"""The suite's hang watchdog: a test past its time is logged with every stack and ends only its
worker; a retry list is written only when hangs were the run's only failures."""

import os
import subprocess
import sys

import pytest

pytestmark = pytest.mark.slow

HANGS = """
import os
import subprocess
import sys
import time

def test_quick():
    pass

def test_hangs():
    if not os.path.exists("hung-once"):  # xdist runs a crashed worker's file again: hang only once
        open("hung-once", "w").close()
        child = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
        open("child-pid", "w").write(str(child.pid))
        time.sleep(60)

def test_after_the_hang():
    pass
"""

FAILS = """
def test_fails():
    assert False
"""


def run_pytest(tmp_path, files: dict[str, str]) -> tuple[int, str, str, str]:
    for name, text in files.items():
        (tmp_path / name).write_text(text)
    log = tmp_path / "hung.log"
    env = {**os.environ, "SPLID_JAX_HANG_LOG": str(log), "SPLID_JAX_TEST_TIMEOUT": "2"}
    env["PYTHONPATH"] = os.pathsep.join([os.getcwd(), env.get("PYTHONPATH", "")])
    argv = [sys.executable, "-m", "pytest", "-q", "-p", "tests.hang_watchdog", "-n", "2", "--dist", "loadfile"]
    argv += ["-c", os.devnull, "--rootdir", str(tmp_path), *files]
    proc = subprocess.run(argv, cwd=tmp_path, env=env, capture_output=True, text=True, timeout=120)
    retry = log.with_name(log.name + ".retry")
    text = [p.read_text() if p.exists() else "" for p in (log, retry)]
    return proc.returncode, proc.stdout.strip().splitlines()[-1], *text


def test_a_hang_is_logged_with_its_stacks_and_the_rest_runs(tmp_path):
    rc, summary, log, retry = run_pytest(tmp_path, {"test_hang.py": HANGS})
    assert rc == 1 and summary.startswith("1 failed")  # the file's other tests ran and passed
    assert "HUNG test_hang.py::test_hangs" in log and "in test_hangs" in log
    assert retry.split() == ["test_hang.py::test_hangs"]
    child = int((tmp_path / "child-pid").read_text())
    assert not os.path.exists(f"/proc/{child}") or " Z " in open(f"/proc/{child}/stat").read()  # killed


def test_no_retry_when_a_test_also_failed(tmp_path):
    rc, summary, log, retry = run_pytest(tmp_path, {"test_hang.py": HANGS, "test_fails.py": FAILS})
    assert rc == 1 and summary.startswith("2 failed") and "HUNG test_hang.py::test_hangs" in log
    assert retry == ""
