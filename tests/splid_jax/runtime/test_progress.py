"""The progress display: a closed stdout (``| head``) silences it and the run goes on to its end."""

import os
import sys

import pytest

from splid_jax import train
from splid_jax.runtime import checkpoint

SMALL = ["--env", "point", "--num-envs", "4", "--eval-episodes", "8", "--eval-every", "5", "--bc-steps", "5",
         "--batch-size", "16", "--hidden", "16", "--iterations", "10"]  # fmt: skip


@pytest.mark.slow
def test_a_closed_stdout_quiets_the_display_and_the_run_goes_on(tmp_path, monkeypatch, capfd):
    read, write = os.pipe()
    os.close(read)  # the reader is gone, as `| head -3` leaves it after three lines
    saved = os.dup(1)
    try:
        os.dup2(write, 1)
        monkeypatch.setattr(sys, "stdout", open(1, "w", closefd=False))
        assert train.main([*SMALL, "--run-dir", str(tmp_path / "run")]) == 0
        sys.stdout.flush()
    finally:
        os.dup2(saved, 1)
        os.close(saved)
        os.close(write)
    assert checkpoint.latest_step(str(tmp_path / "run")) == 10
    assert "Error" not in capfd.readouterr().err
