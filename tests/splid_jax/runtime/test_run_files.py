"""A run directory is always continued from its last whole checkpoint, or started again where it has
none: a real process killed after its first metrics line and before its first checkpoint, for a run,
a sweep and a figure."""

import json
import os
import signal
import subprocess
import sys

import pytest

from splid_jax import figures, sweep, train
from splid_jax.runtime import checkpoint

# Every checkpoint save blocks: the process is killed in the gap between a chunk's metrics line and its
# checkpoint, which a real run opens for the save's length.
SAVES_NEVER_END = """
import runpy, sys, threading
from splid_jax.runtime import checkpoint
def save(run_dir, step, *a, **kw):
    print("saving", step, flush=True)
    threading.Event().wait()
checkpoint.save = save
module = sys.argv.pop(1)
runpy.run_module(module, run_name="__main__", alter_sys=True)
"""

SMALL = ["--num-envs", "4", "--eval-episodes", "8", "--eval-every", "5", "--bc-steps", "5", "--batch-size", "16",
         "--hidden", "16", "--iterations", "10"]  # fmt: skip
QUICK = ["--quick", "--seeds", "1", "--episodes", "80", "--set", "eval_episodes=8", "--set", "hidden=16"]
COMMANDS = {  # the first command, and the one that continues it, given the directory
    "train": (train, lambda d: ["--env", "point", *SMALL, "--run-dir", d], lambda d: ["--resume", d]),
    "sweep": (
        sweep,
        lambda d: ["--env", "point", *SMALL, "--seeds", "2", "--no-plot", "--run-dir", d],
        lambda d: ["--resume", d, "--no-plot"],
    ),
    "figures": (figures, lambda d: ["fig8", *QUICK, "--out", d], lambda d: ["fig8", "--out", d, "--resume"]),
}


def killed_in_the_gap(module: str, args: list[str]) -> None:
    proc = subprocess.Popen([sys.executable, "-c", SAVES_NEVER_END, module, *args, "--quiet"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)  # fmt: skip
    try:
        for line in proc.stdout:
            if line.startswith("saving"):
                break
        else:
            raise AssertionError(f"the run ended before its first save: {proc.stderr.read()}")
    finally:
        proc.send_signal(signal.SIGKILL)
        proc.communicate(timeout=60)


def metrics_files(root: str) -> list[str]:
    return sorted(os.path.join(d, f) for d, _, files in os.walk(root) for f in files if f == "metrics.jsonl")


def iterations(path: str) -> list[int]:
    with open(path) as fh:
        return [json.loads(line)["iteration"] for line in fh]


@pytest.mark.slow
@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_a_run_killed_before_its_first_checkpoint_starts_again_on_resume(tmp_path, capsys, command):
    module, first, again = COMMANDS[command]
    run_dir = str(tmp_path / "run")
    killed_in_the_gap(module.__name__, first(run_dir))
    recorded = metrics_files(run_dir)
    assert recorded and any(iterations(p) for p in recorded)  # the gap: records, and no checkpoint
    assert all(checkpoint.latest_step(os.path.dirname(p)) is None for p in recorded + [os.path.join(run_dir, "x")])
    before = {p: open(p).read() for p in recorded}  # the first command again says how to go on, and changes nothing
    assert module.main([*first(run_dir), "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "--resume" in err
    assert {p: open(p).read() for p in recorded} == before
    assert module.main([*again(run_dir), "--quiet"]) == 0
    for path in metrics_files(run_dir):  # each record once, up to the checkpoint the run ends on
        done = iterations(path)
        assert done and done == list(range(5, done[-1] + 1, 5)), path
        assert checkpoint.latest_step(os.path.dirname(os.path.dirname(path))) in (done[-1], None)


@pytest.mark.parametrize("inside", ["R0/checkpoints/10", "R0/sub/run", "S/member/run"])
def test_a_run_dir_inside_another_run_is_refused(tmp_path, capsys, inside):
    (tmp_path / "R0" / "checkpoints" / "10").mkdir(parents=True)
    (tmp_path / "R0" / "config.json").write_text("{}")
    (tmp_path / "S" / "member").mkdir(parents=True)
    (tmp_path / "S" / "sweep.json").write_text("{}")
    run_dir = tmp_path / inside
    assert train.main(["--env", "point", "--iterations", "5", "--run-dir", str(run_dir)]) == 2
    err = capsys.readouterr().err.strip()
    outer = tmp_path / inside.split("/")[0]
    assert len(err.splitlines()) == 1 and f"outside any other run (it lies in {outer})" in err
    assert not (run_dir / "metrics.jsonl").exists()


def test_a_config_json_alone_makes_no_run_to_stay_out_of(tmp_path):
    from splid_jax.runtime.run_files import enclosing_run

    (tmp_path / "config.json").write_text("{}")  # some other program's
    assert enclosing_run(str(tmp_path / "runs" / "a")) is None
    (tmp_path / "metrics.jsonl").write_text("")
    assert enclosing_run(str(tmp_path / "runs" / "a")) == str(tmp_path)


def _garbage_run(root, file: str, content: bytes):
    """A run R and a sweep S with member m0, one of whose files holds ``content``."""
    for d in ("R", "S/m0", "F"):
        (root / d).mkdir(parents=True)
    config = json.dumps({"env": "point", "iterations": 5})
    for path in ("R/config.json", "S/m0/config.json"):
        (root / path).write_text(config)
    (root / "R" / "metrics.jsonl").write_text('{"iteration": 5}\n')
    (root / "S" / "sweep.json").write_text(json.dumps({"config": {"env": "point"}, "members": [{"run_dir": "m0"}]}))
    (root / "F" / "figure.json").write_text(json.dumps({"figure": "fig8"}))
    (root / file).write_bytes(content)


GARBAGE = [  # (file, the command reading it, given the root)
    ("R/config.json", "rollout", lambda r: [f"{r}/R"]),
    ("R/config.json", "export", lambda r: [f"{r}/R", "--out", f"{r}/out"]),
    ("R/config.json", "train", lambda r: ["--resume", f"{r}/R"]),
    ("R/metrics.jsonl", "plot", lambda r: [f"{r}/R"]),
    ("F/figure.json", "figures", lambda r: ["fig8", "--out", f"{r}/F", "--replot"]),
    ("F/figure.json", "figures", lambda r: ["fig8", "--out", f"{r}/F", "--resume"]),
    ("S/sweep.json", "sweep", lambda r: ["--resume", f"{r}/S"]),
    ("S/sweep.json", "export", lambda r: [f"{r}/S/m0", "--out", f"{r}/out"]),
]


@pytest.mark.parametrize("content", [b'{"env": "\xff"}', b"[1, 2]"], ids=["not-utf8", "a-list"])
@pytest.mark.parametrize("file, command, argv", GARBAGE, ids=[f"{c}-{f}-{i}" for i, (f, c, _) in enumerate(GARBAGE)])
def test_an_undecodable_or_foreign_file_is_one_line_and_exit_2(tmp_path, capsys, content, file, command, argv):
    import importlib

    _garbage_run(tmp_path, file, content)
    assert importlib.import_module(f"splid_jax.{command}").main(argv(tmp_path)) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err, err
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("records, code", [(3, 2), (2, 0)], ids=["checkpoints-deleted", "killed-in-the-gap"])
def test_records_beyond_the_gap_without_a_checkpoint_are_not_dropped(tmp_path, capsys, records, code):
    from splid_jax.config import TrainConfig
    from splid_jax.runtime.run_files import check_run_dir

    cfg = TrainConfig(env="point", iterations=15, eval_every=5, run_dir=str(tmp_path))
    (tmp_path / "config.json").write_text(json.dumps(cfg.to_json()))
    lines = "".join(f'{{"iteration": {5 * i}}}\n' for i in range(1, records + 1))
    (tmp_path / "metrics.jsonl").write_text(lines)
    if code == 0:  # at most a chunk past the first checkpoint under way: the run starts again
        assert check_run_dir(cfg, resume=True) is None
        return
    assert train.main(["--resume", str(tmp_path), "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and f"invalid --resume {tmp_path}: must be a run with a checkpoint" in err
    assert (tmp_path / "metrics.jsonl").read_text() == lines


def test_a_slide_run_from_before_the_pads_default_is_told_the_options_of_its_task():
    import envs
    from splid_jax.common.errors import InvalidConfig
    from splid_jax.config import TrainConfig
    from splid_jax.runtime.run_files import env_settings, recorded_task

    was = env_settings(envs.make("slide", finger="box", finger_table=0.0, drive="pd", gripper_mass=0.0, hand_pitch=0.0))
    assert "gripper_mass" not in was and "hand_pitch" not in was  # as runs recorded before the option existed
    cfg, now = TrainConfig(env="slide", run_dir="R"), env_settings(envs.make("slide"))
    spelt = "finger=box,drive=pd,finger_table=0.0,gripper_mass=0.0,hand_pitch=0.0"
    named = "differ \\(finger, drive, finger_table, gripper_mass, hand_pitch\\)"
    with pytest.raises(InvalidConfig, match=f"{named}: --env-options {spelt}$"):
        recorded_task(cfg, {"env": was}, now)
    recorded_task(TrainConfig(env="slide", run_dir="R", env_options=spelt), {"env": was}, was)  # its own task: resumes
