"""The command line and its run directory in this process: bad input, NaN, corrupt and mismatched
checkpoints, resumes refused or warned of. All on the point task (test_train_processes.py: signals and kills)."""

import dataclasses
import json
import os
import shutil

import jax
import numpy as np
import pytest

from splid_jax.config import TrainConfig
from splid_jax.learners import registry
from splid_jax.learners.splid.trainer import Trainer
from splid_jax.runtime import checkpoint
from splid_jax.train import RunStopped, main, run

TINY = ["--env", "point", "--num-envs", "8", "--eval-episodes", "16", "--bc-steps", "40", "--batch-size", "64",
        "--hidden", "32,32", "--eval-every", "5"]  # fmt: skip
VOLATILE = {"wall_s", "steps_per_s"}
# TINY's run in-process: the programs its first run compiled come from the compile cache
TINY_CONFIG = dict(env="point", num_envs=8, eval_episodes=16, bc_steps=40, batch_size=64, hidden=(32, 32), eval_every=5)


def stable(path):
    with open(os.path.join(path, "metrics.jsonl")) as fh:
        return [{k: v for k, v in json.loads(line).items() if k not in VOLATILE} for line in fh]


@pytest.mark.parametrize(
    "args,field",
    [
        (["--sigma", "-1"], "--sigma "),
        (["--horizon", "0"], "--horizon "),
        (["--horizon", "50"], "--horizon "),
        (["--num-envs", "0"], "--num-envs "),
        (["--policy-ema", "1"], "--policy-ema "),
        (["--env", "nope"], "--env "),
        (["--iterations", "7", "--eval-every", "5"], "--iterations "),
        (["--env-options", "success_radius"], "--env-options "),
        (["--env-options", "bogus=1"], "invalid --env-options bogus=1: must be one of the fields"),
        (["--env-options", "max_episode_steps=8"], "--horizon "),  # H = 8 must stay below the episode length
        (["--env-options", "max_episode_steps=abc"], "invalid --env-options max_episode_steps=abc:"),
        (["--env-options", "success_radius=big"], "invalid --env-options success_radius=big:"),
        (["--env-options", "max_episode_steps=20.5"], "invalid --env-options max_episode_steps=20.5:"),
        (["--seed", "99999999999999999999"], "--seed "),
        (["--sigma", "inf"], "--sigma "),
        (["--sigma", "nan"], "--sigma "),
        (["--num-envs", "100000000"], "--num-envs "),  # refused from its shapes, before anything is allocated
        (["--run-dir", ""], "--run-dir "),
        (["--run-dir", "bad-\udcff"], "--run-dir "),  # a \xff byte in the name: orbax takes UTF-8 paths only
        (["--bc-steps", "0"], "--bc-steps "),  # no cloning step: the loss would be undefined
        (["--gcsl-relabel", "future"], "--gcsl-relabel "),  # flags the learner does not read
        (["--pchid-every", "3"], "--pchid-every "),
        (["--algo", "gcsl", "--select"], "--select "),
        (["--algo", "gcsl", "--relabel", "stop"], "--relabel "),
        (["--algo", "gcsl", "--horizon", "3"], "--horizon "),
        (["--algo", "gcsl", "--select-lanes", "0.5"], "--select-lanes "),
        (["--algo", "pchid", "--gcsl-relabel", "final"], "--gcsl-relabel "),
        (["--iterations", str(10**20)], "--iterations "),
        (["--batch-size", "2000000000"], "--batch-size 2000000000"),  # the sizes named are the ones given
        (["--env-options", "success_radius=1,success_radius=2"], "--env-options "),  # which one was meant?
        (["--her-batch-size", "64"], "invalid --her-batch-size 64: must be unset unless --algo her"),  # as typed
        (["--algo", "gcsl", "--her-layer-norm"], "invalid --her-layer-norm True: must be unset unless --algo her"),
    ],
)
def test_bad_values_stop_before_any_work(tmp_path, capsys, args, field):
    run_dir = tmp_path / "run"
    assert main(["--run-dir", str(run_dir), *args]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and field in err
    assert not run_dir.exists()


def test_abbreviated_flags_are_not_taken_for_others(tmp_path, capsys):
    with pytest.raises(SystemExit) as exc:
        main(["--learning-rat", "0.1", "--run-dir", str(tmp_path / "run")])
    assert exc.value.code == 2 and "--learning-rat" in capsys.readouterr().err
    assert not (tmp_path / "run").exists()


@pytest.mark.parametrize("args", [["--nope"], ["--iterations", "x"]])
def test_a_typo_is_one_line_pointing_at_help(tmp_path, capsys, args):
    with pytest.raises(SystemExit) as exc:
        main([*args, "--run-dir", str(tmp_path / "run")])
    err = capsys.readouterr().err.strip()
    assert exc.value.code == 2 and len(err.splitlines()) == 1 and err.endswith("--help)")
    assert not (tmp_path / "run").exists()


def test_a_run_dir_under_proc_is_refused(capsys):
    assert main(["--run-dir", "/proc/splid-run"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "--run-dir" in err and "writable" in err


def test_env_options_help_lists_every_tasks_fields(capsys):
    with pytest.raises(SystemExit):
        main(["--help"])
    out = " ".join(capsys.readouterr().out.split())
    assert "point: max_episode_steps=50, success_radius=1.0" in out
    assert "push: " in out and "distance_threshold=0.05" in out and "slide: as " in out


def test_run_dir_that_is_a_file_is_refused(tmp_path, capsys):
    f = tmp_path / "file"
    f.write_text("x")
    assert main(["--run-dir", str(f)]) == 2
    assert "run_dir" in capsys.readouterr().err


def test_help_documents_every_flag(capsys):
    """Every field of the run config is a flag with its help line, and every field of a learner's own
    settings is a flag of its own (``--her-batch-size``) with its default, under its learner's group."""
    with pytest.raises(SystemExit) as exc:
        main(["--help"])
    assert exc.value.code == 0
    out = " ".join(capsys.readouterr().out.split())
    for f in TrainConfig.settings_fields():
        flag = "--" + f.name.replace("_", "-")
        help_start = " ".join(f.metadata["help"].split()[:4])
        assert f"{flag} " in out and help_start in out, f.name
    assert "--no-select" in out and "--resume" in out
    for learner in registry.LEARNERS.values():
        if learner.options is not None:
            for f in dataclasses.fields(learner.settings):
                default = ",".join(map(str, f.default)) if isinstance(f.default, tuple) else f.default
                flag = f"--{learner.name}-{f.name.replace('_', '-')}"
                assert f"{flag} " in out and f"(default: {default})" in out, flag
    assert "read only by splid, gcsl, pchid:" in out and "her's own settings (read only by her):" in out
    assert "--preset PRESET" in out and "tuned (" in out and "paper (" in out


def test_an_error_names_the_flags_the_user_typed(tmp_path, capsys):
    assert main(["--env", "push", "--iterations", "3", "--run-dir", str(tmp_path / "run")]) == 2
    err = capsys.readouterr().err.strip()
    assert err == "python -m splid_jax.train: error: invalid --iterations 3: must be a multiple of --eval-every 5"
    assert main(["--algo", "her", "--her-batch-size", "0", "--run-dir", str(tmp_path / "run")]) == 2
    assert "invalid --her-batch-size 0: must be an integer >= 1" in capsys.readouterr().err
    assert not (tmp_path / "run").exists()


@pytest.mark.slow
def test_nan_stops_the_run_and_keeps_the_last_good_checkpoint(tmp_path):
    cfg = TrainConfig(**TINY_CONFIG, iterations=20, learning_rate=1e38, run_dir=str(tmp_path / "run"))
    with pytest.raises(RunStopped, match="non-finite"):
        run(cfg, quiet=True)
    step = checkpoint.latest_step(cfg.run_dir)
    assert step is not None and step < 20
    trainer = Trainer(__import__("envs").make("point"), cfg)
    _, state, _ = checkpoint.restore(cfg.run_dir, trainer.init(jax.random.PRNGKey(0)))
    assert all(np.isfinite(np.asarray(x)).all() for x in jax.tree_util.tree_leaves(state.policy.params))


@pytest.mark.slow
def test_corrupt_and_mismatched_checkpoints_fail_clearly(tmp_path, capsys, monkeypatch):
    from splid_jax.runtime import programs

    run_dir = tmp_path / "run"
    assert main([*TINY, "--iterations", "5", "--run-dir", str(run_dir), "--quiet"]) == 0
    assert main(["--resume", str(run_dir), "--hidden", "8"]) == 2  # a changed network is not this run
    assert "hidden" in capsys.readouterr().err
    cfg = json.loads((run_dir / "config.json").read_text())
    (run_dir / "config.json").write_text(json.dumps({**cfg, "hidden": [8]}))
    with monkeypatch.context() as m:  # an edited config.json is refused before anything compiles
        m.setattr(programs, "compile_all", lambda *a, **k: pytest.fail("compiled before the checkpoint was checked"))
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
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1
    assert f"error: checkpoint {run_dir / 'checkpoints' / '5'} is corrupt or unreadable (" in err


def test_env_options_build_the_task_the_run_trains_on(tmp_path):
    run_dir = tmp_path / "run"
    args = ["--run-dir", str(run_dir), "--iterations", "5", "--num-envs", "4", "--bc-steps", "2"]
    args += ["--eval-episodes", "4"]
    assert main([*args, "--env-options", "max_episode_steps=20,success_radius=0.5", "--quiet"]) == 0
    cfg = json.load(open(run_dir / "config.json"))
    assert cfg["env_options"] == "max_episode_steps=20,success_radius=0.5"
    assert cfg["physics"] is None  # the point task has no choice of physics code; a Fetch task records its own
    rec = json.loads(open(run_dir / "metrics.jsonl").readline())
    assert rec["env_steps"] == 5 * 4 * 20  # episodes of the overridden length


def test_resume_under_changed_task_defaults_names_the_options_that_rebuild_the_recorded_task(tmp_path, capsys):
    # a run recorded when the point task's doors were 0.5 wide by default: its config.json spells no option
    run_dir = tmp_path / "run"
    assert main([*TINY, "--iterations", "5", "--run-dir", str(run_dir), "--env-options", "door_half_width=0.5"]) == 0
    saved = json.load(open(run_dir / "config.json"))
    (run_dir / "config.json").write_text(json.dumps({**saved, "env_options": ""}))
    capsys.readouterr()
    assert main(["--resume", str(run_dir), "--iterations", "10", "--quiet"]) == 2
    err = capsys.readouterr().err
    spelt = "door_half_width=0.5"
    assert len(err.splitlines()) == 1 and err.rstrip().endswith(f"differ (door_half_width): --env-options {spelt}")
    assert main(["--resume", str(run_dir), "--iterations", "10", "--env-options", spelt, "--quiet"]) == 0
    assert json.load(open(run_dir / "config.json"))["env_options"] == "door_half_width=0.5"  # recorded from now on
    assert [json.loads(x)["iteration"] for x in open(run_dir / "metrics.jsonl")] == [5, 10]


def test_resume_to_fewer_iterations_is_refused_and_a_finished_run_is_complete(tmp_path, capsys):
    run_dir = tmp_path / "run"
    assert main([*TINY, "--iterations", "10", "--run-dir", str(run_dir), "--quiet"]) == 0
    files = {p: (run_dir / p).read_bytes() for p in ("config.json", "metrics.jsonl")}
    capsys.readouterr()
    assert main(["--resume", str(run_dir), "--iterations", "5"]) == 2
    err = capsys.readouterr().err
    assert "--iterations 5" in err and ">= 10" in err
    assert main(["--resume", str(run_dir)]) == 0
    assert "already complete" in capsys.readouterr().out
    assert {p: (run_dir / p).read_bytes() for p in files} == files


def test_metrics_without_a_checkpoint_are_not_overwritten(tmp_path, capsys):
    run_dir = tmp_path / "run"
    run_dir.mkdir()
    (run_dir / "metrics.jsonl").write_text('{"iteration": 5}\n' * 30)
    assert main([*TINY, "--iterations", "5", "--run-dir", str(run_dir)]) == 2
    assert "--run-dir" in capsys.readouterr().err
    assert (run_dir / "metrics.jsonl").read_text() == '{"iteration": 5}\n' * 30


def test_bad_resumes_and_bad_saved_configs_are_one_line(tmp_path, capsys):
    run_dir = tmp_path / "run"
    assert main([*TINY, "--iterations", "5", "--run-dir", str(run_dir), "--quiet"]) == 0
    files = {p: (run_dir / p).read_bytes() for p in ("config.json", "metrics.jsonl")}
    capsys.readouterr()
    assert main(["--resume", str(run_dir), "--run-dir", str(tmp_path / "x"), "--iterations", "10"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "invalid --run-dir " in err and "unset with --resume" in err
    assert not (tmp_path / "x").exists()
    saved = json.loads(files["config.json"])
    for field, value in [("sigma", "high"), ("hidden", ["a", 64, 64]), ("num_envs", 32.5)]:
        (run_dir / "config.json").write_text(json.dumps({**saved, field: value}))
        assert main(["--resume", str(run_dir), "--iterations", "10"]) == 2
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1 and f"invalid --{field.replace('_', '-')} " in err, err
    (run_dir / "config.json").write_bytes(files["config.json"])
    assert (run_dir / "metrics.jsonl").read_bytes() == files["metrics.jsonl"]
    assert checkpoint.latest_step(str(run_dir)) == 5
    (run_dir / "metrics.jsonl").unlink()  # its records cannot be made again: the resume says so
    assert main(["--resume", str(run_dir), "--iterations", "10", "--quiet"]) == 0
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "warning:" in err and "missing or empty" in err and "1-5 are lost" in err
    assert [r["iteration"] for r in stable(run_dir)] == [10]
    shutil.rmtree(run_dir / "checkpoints")  # as a run stopped before its first save leaves it
    (run_dir / "metrics.jsonl").write_text("")
    assert main(["--resume", str(run_dir), "--iterations", "10"]) == 0
    assert "stopped before its first checkpoint; starting it again" in capsys.readouterr().out
    assert [r["iteration"] for r in stable(run_dir)] == [5, 10] and checkpoint.latest_step(str(run_dir)) == 10


def test_an_unreadable_run_is_not_called_missing(tmp_path, capsys, monkeypatch):
    (tmp_path / "config.json").write_text("{}")
    real_access = os.access  # permissions that bar even root, as a read-only share does for others
    monkeypatch.setattr(os, "access", lambda p, m: not str(p).endswith("config.json") and real_access(p, m))
    assert main(["--resume", str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "whose config.json can be read (Permission denied)" in err


def test_a_torn_record_at_the_checkpoint_is_warned_of(tmp_path, capsys):
    from splid_jax.runtime.run_files import warn_of_gap

    warn_of_gap("m.jsonl", [{"iteration": 5}, {"iteration": 10}], 10)
    assert capsys.readouterr().err == ""
    warn_of_gap("m.jsonl", [{"iteration": 5}], 10)  # the record of 10 was torn
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "ends at iteration 5" in err and "6-10 are lost" in err


@pytest.mark.slow
@pytest.mark.parametrize(
    "error, said",
    [
        (OSError(28, "No space left on device"), "no space left on the device"),
        (OSError(30, "Read-only file system", "ckpt"), "cannot write RUN (Read-only file system: ckpt)"),
        (ValueError("PERMISSION_DENIED: Error opening file [os_error_code='13']"), "cannot write RUN (Permission"),
    ],
    ids=["full", "read-only", "permission"],
)
def test_a_failed_write_is_one_line_exit_3_and_keeps_the_last_whole_checkpoint(tmp_path, capsys, monkeypatch,
                                                                               error, said):  # fmt: skip
    real_save, saves = checkpoint.save, []

    def fails(run_dir, step, *a, **kw):
        saves.append(step)
        if len(saves) > 1:
            raise error
        return real_save(run_dir, step, *a, **kw)

    monkeypatch.setattr(checkpoint, "save", fails)
    run_dir = tmp_path / "run"
    args = [*TINY, "--iterations", "15", "--checkpoint-every", "1", "--run-dir", str(run_dir), "--quiet"]
    assert main(args) == 3
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and said.replace("RUN", str(run_dir)) in err and "iteration 5 is kept" in err
    assert checkpoint.latest_step(str(run_dir)) == 5


def test_a_gpu_compiler_failing_on_the_solve_kernel_is_one_line(tmp_path, capsys, monkeypatch):
    from envs.base import GoalEnv

    def compile_fails(self):
        raise RuntimeError("INTERNAL: Triton compilation failed for the kernel\n(a long log)")

    monkeypatch.setattr(jax.stages.Lowered, "compile", compile_fails)
    monkeypatch.setattr(GoalEnv, "kernel_fallback", lambda self, e: "another solver (" + str(e).split()[1] + ")")
    assert main([*TINY, "--iterations", "5", "--run-dir", str(tmp_path / "run")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "--env-options" in err and "another solver (Triton)" in err


def test_resuming_a_sweeps_member_is_refused_and_changes_nothing(tmp_path, capsys):
    member = tmp_path / "sweep" / "m0"
    member.mkdir(parents=True)
    (tmp_path / "sweep" / "sweep.json").write_text("{}")
    config = json.dumps(TrainConfig(env="point", iterations=5, eval_every=5, run_dir=str(member)).to_json())
    (member / "config.json").write_text(config)
    (member / "metrics.jsonl").write_text('{"iteration": 5}\n')
    assert main(["--resume", str(member), "--iterations", "10"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "not a member of a sweep" in err and "sweep --resume" in err
    assert (member / "config.json").read_text() == config and (member / "metrics.jsonl").read_text().count("\n") == 1
    assert sorted(p.name for p in member.iterdir()) == ["config.json", "metrics.jsonl"]
