"""A grid of seeds x sigma x H (x --vary's traced settings) runs as one vmapped program and writes one
metrics file per member."""

import json

import pytest

from splid_jax import sweep
from splid_jax.config import TrainConfig


def read(path):
    return [json.loads(line) for line in path.read_text().splitlines()]


def test_grid_runs_as_one_program_with_a_file_per_member(tmp_path):
    cfg = TrainConfig(env="point", num_envs=4, eval_episodes=16, iterations=4, eval_every=2, bc_steps=5,
                      batch_size=16, hidden=(16,), horizon=4, run_dir=str(tmp_path))  # fmt: skip
    grid = sweep.members(2, (0.0, 1.0), (2, 4))
    assert len(grid) == 8
    last = sweep.run_sweep(cfg, grid, quiet=True)
    assert len(last) == 8
    by_name = {m.name: read(tmp_path / m.name / "metrics.jsonl") for m in grid}
    assert all(len(recs) == 2 and recs[-1]["iteration"] == 4 for recs in by_name.values())
    # H sets the replay work; sigma = 0 explores with no noise, sigma = 1 with noise
    assert by_name["sigma1-H2-s0"][-1]["select_steps"] < by_name["sigma1-H4-s0"][-1]["select_steps"]
    assert by_name["sigma1-H4-s0"][-1]["select_pairs"] != by_name["sigma0-H4-s0"][-1]["select_pairs"]
    assert by_name["sigma1-H4-s0"] != by_name["sigma1-H4-s1"]  # seeds differ
    config = json.loads((tmp_path / "sigma0-H2-s1" / "config.json").read_text())
    assert (config["sigma"], config["horizon"], config["seed"]) == (0.0, 2, 1)


def test_vary_grids_over_traced_settings_in_one_program(tmp_path):
    args = ["--env", "point", "--num-envs", "4", "--eval-episodes", "8", "--iterations", "2", "--eval-every", "2",
            "--bc-steps", "5", "--batch-size", "16", "--hidden", "16", "--seeds", "1", "--horizons", "4",
            "--no-plot", "--quiet", "--run-dir", str(tmp_path)]  # fmt: skip
    vary = ["--vary", "learning_rate=0.001,0.1", "--vary", "policy_ema=0,0.9"]
    assert sweep.main([*args, *vary]) == 0
    names = sorted(p.name for p in tmp_path.iterdir() if p.is_dir() and p.name != "checkpoints")
    grid = [(lr, ema) for lr in ("0.001", "0.1") for ema in ("0", "0.9")]
    assert names == [f"sigma1-H4-learning_rate{lr}-policy_ema{ema}-s0" for lr, ema in grid]
    config = json.loads((tmp_path / names[1] / "config.json").read_text())
    assert (config["learning_rate"], config["policy_ema"]) == (0.001, 0.9)
    base = json.loads((tmp_path / "sweep.json").read_text())["config"]
    assert (base["learning_rate"], base["policy_ema"]) == (0.1, 0.9)  # the acting average kept for all
    losses = {n: read(tmp_path / n / "metrics.jsonl")[-1]["bc_loss"] for n in names}
    assert len(set(losses.values())) == 4  # each member trains with its own rate and average


def test_vary_horizon_end_lets_each_member_anneal_its_own_horizon(tmp_path):
    args = ["--env", "point", "--num-envs", "4", "--eval-episodes", "8", "--iterations", "4", "--eval-every", "2",
            "--bc-steps", "5", "--batch-size", "16", "--hidden", "16", "--seeds", "1", "--horizons", "6",
            "--sigma-anneal", "4", "--no-plot", "--quiet", "--run-dir", str(tmp_path)]  # fmt: skip
    assert sweep.main([*args, "--vary", "horizon_end=0,2"]) == 0
    horizons = {n: [r["horizon"] for r in read(tmp_path / f"sigma1-H6-horizon_end{n}-s0" / "metrics.jsonl")]
                for n in (0, 2)}  # fmt: skip
    assert horizons == {0: [6, 6], 2: [5, 2]}  # iterations 2 and 4 of a fall from 6 to 2 over 4


def test_members_take_the_tasks_falling_horizon_unless_horizons_are_given(tmp_path):
    given = {"env": "push", "run_dir": str(tmp_path)}
    _, lanes = sweep.grid_configs(given, 2, (1.0,), None)
    assert {(m.horizon, m.horizon_end) for m in lanes} == {(12, 8)}
    _, lanes = sweep.grid_configs(given, 1, (1.0,), (4, 8))
    assert [(m.horizon, m.horizon_end) for m in lanes] == [(4, 0), (8, 0)]  # each H throughout
    _, lanes = sweep.grid_configs(given, 1, (1.0,), None, {"horizon_end": (0, 6)})
    assert [(m.horizon, m.horizon_end) for m in lanes] == [(12, 0), (12, 6)]


def test_a_varied_window_resolves_pushs_widening_as_a_given_one_would(tmp_path):
    given = {"env": "push", "run_dir": str(tmp_path)}
    window = lambda lanes: [(m.buffer_size, m.buffer_window, m.buffer_window_grow) for m in lanes]  # noqa: E731
    _, lanes = sweep.grid_configs(given, 1, (1.0,), None, {"buffer_window": (0, 50_000)})
    assert window(lanes) == [(200_000, 0, 0), (200_000, 50_000, 0)]  # as --buffer-window W: a fixed window
    _, lanes = sweep.grid_configs(given, 1, (1.0,), None, {"buffer_window_grow": (100, 400)})
    assert window(lanes) == [(200_000, 50_000, 100), (200_000, 50_000, 400)]
    _, lanes = sweep.grid_configs(given, 1, (1.0,), None)
    assert window(lanes) == [(200_000, 50_000, 200)]


@pytest.mark.parametrize(
    "vary, field",
    [
        ("horizon=2,4", "vary"),  # H has its own flag
        ("learning_rate", "vary"),
        ("batch_size=16,32", "vary"),  # a shape, not a traced setting
        ("learning_rate=a,b", "learning_rate"),
        ("learning_rate=-1,0.1", "learning_rate"),
        ("learning_rate=inf", "learning_rate"),
        ("policy_ema=0.5,0.5", "policy_ema"),
        ("sigma_end=0.5,2", "sigma_end"),
        ("gripper_hold=1,5", "gripper_hold"),  # point has no fingers to hold
        ("gripper_hold=1.5", "gripper_hold"),
        ("horizon_end=2,99", "horizon_end"),  # above the horizon
    ],
)
def test_vary_names_the_field_of_a_bad_value(capsys, tmp_path, vary, field):
    assert sweep.main(["--env", "point", "--vary", vary, "--run-dir", str(tmp_path / "x")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and f"invalid --{field.replace('.', '-').replace('_', '-')} " in err
    assert not (tmp_path / "x").exists()


def test_vary_refuses_a_field_given_twice_or_one_the_learner_does_not_trace(capsys, tmp_path):
    for args, field in [(["--learning-rate", "0.001", "--vary", "learning_rate=0.001,0.01"], "learning_rate"),
                        (["--algo", "her", "--vary", "learning_rate=0.001,0.01"], "vary"),
                        (["--algo", "pchid", "--vary", "horizon_end=0,2"], "vary")]:  # fmt: skip
        assert sweep.main(["--env", "point", *args, "--run-dir", str(tmp_path / "x")]) == 2
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1 and f"invalid --{field.replace('.', '-').replace('_', '-')} " in err
    assert not (tmp_path / "x").exists()


def test_cli_rejects_a_bad_grid(capsys, tmp_path):
    assert sweep.main(["--env", "point", "--horizons", "0,4", "--run-dir", str(tmp_path / "x")]) == 2
    assert "horizons" in capsys.readouterr().err
    assert not (tmp_path / "x").exists()


@pytest.mark.parametrize(
    "args, field",
    [
        (["--sigmas", ""], "sigmas"),
        (["--sigmas", "a,b"], "sigmas"),
        (["--sigmas", "-1,1"], "sigmas"),
        (["--sigmas", "inf"], "sigmas"),
        (["--horizons", "2.5"], "horizons"),
        (["--seed", "-1"], "seed"),
        (["--horizons", "4,4"], "horizons"),  # two members would share one directory
        (["--sigmas", "1,1.0"], "sigmas"),
        (["--algo", "gcsl", "--horizons", "2,4"], "horizons"),  # GCSL selects nothing: H is not read
        (["--algo", "her", "--sigmas", "0.5"], "sigmas"),
        (["--her-batch-size", "64"], "her_batch_size"),  # another learner's own flag, as typed
    ],
)
def test_cli_names_the_field_of_a_bad_value(capsys, tmp_path, args, field):
    assert sweep.main(["--env", "point", *args, "--run-dir", str(tmp_path / "x")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and f"invalid --{field.replace('.', '-').replace('_', '-')} " in err
    assert not (tmp_path / "x").exists()


def test_a_grid_too_large_for_memory_is_refused_before_it_is_stacked(capsys, tmp_path, monkeypatch):
    from splid_jax.runtime import loop

    def stack(*a, **kw):
        raise AssertionError("stacked before the size check")

    monkeypatch.setattr(loop, "_lane_hyper", stack)
    args = ["--env", "point", "--iterations", "5", "--eval-every", "5", "--seeds", "2000", "--buffer-size", "20000000"]
    assert sweep.main([*args, "--run-dir", str(tmp_path / "x")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "2000 sweep members" in err and "per member" in err
    assert not (tmp_path / "x").exists()


def test_cli_refuses_abbreviated_flags(capsys, tmp_path):
    with pytest.raises(SystemExit) as exc:
        sweep.main(["--env", "point", "--sigma", "1", "--run-dir", str(tmp_path / "x")])
    assert exc.value.code == 2 and "--sigma" in capsys.readouterr().err
    assert not (tmp_path / "x").exists()


def test_a_second_sweep_into_one_dir_is_refused_and_a_sweep_resumes(capsys, tmp_path):
    args = ["--env", "point", "--num-envs", "4", "--eval-episodes", "8", "--eval-every", "2", "--bc-steps", "5",
            "--batch-size", "16", "--hidden", "16", "--seeds", "2", "--horizons", "4", "--no-plot",
            "--quiet"]  # fmt: skip
    run_dir = str(tmp_path / "sweep")
    assert sweep.main([*args, "--iterations", "2", "--run-dir", run_dir]) == 0
    kept = read(tmp_path / "sweep" / "sigma1-H4-s0" / "metrics.jsonl")
    assert sweep.main([*args, "--iterations", "4", "--sigmas", "0.5", "--run-dir", run_dir]) == 2
    assert "--run-dir" in capsys.readouterr().err
    assert read(tmp_path / "sweep" / "sigma1-H4-s0" / "metrics.jsonl") == kept
    other_grids = [(["--seeds", "3"], "seeds"), (["--sigmas", "0.5"], "sigmas"), (["--horizons", "2"], "horizons"),
                   (["--vary", "learning_rate=0.01"], "learning_rate")]  # fmt: skip
    for grid, field in other_grids:
        assert sweep.main(["--resume", run_dir, *grid, "--iterations", "4", "--no-plot", "--quiet"]) == 2
        err = capsys.readouterr().err.strip()
        flag = f"--{field.replace('_', '-')} "
        assert len(err.splitlines()) == 1 and f"invalid {flag}" in err and "as in the sweep being resumed" in err
    assert read(tmp_path / "sweep" / "sigma1-H4-s0" / "metrics.jsonl") == kept
    same = ["--seeds", "2", "--sigmas", "1", "--horizons", "4"]  # the grid it started with may be given again
    assert sweep.main(["--resume", run_dir, *same, "--iterations", "4", "--no-plot", "--quiet"]) == 0
    recs = read(tmp_path / "sweep" / "sigma1-H4-s1" / "metrics.jsonl")
    assert [r["iteration"] for r in recs] == [2, 4]
