"""Figures from one command: every method one vmapped sweep on the same episode budget, a PNG and a
CSV drawn from the run directories alone, and one-line refusals of bad input."""

import csv
import json
import os
from pathlib import Path

import numpy as np
import pytest

from splid_jax import figures
from splid_jax.runtime import loop

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
QUICK = ["--quick", "--seeds", "2", "--episodes", "160", "--set", "eval_episodes=20", "--quiet"]
TRAINED = ("splid", "no-select", "gcsl")


def rows(path: Path) -> list[dict]:
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


@pytest.fixture(scope="module")
def fig3(tmp_path_factory):
    """One quick Figure 3 of three methods, trained once for the tests that read it."""
    out = tmp_path_factory.mktemp("fig3") / "out"
    code = figures.main(["fig3", "--methods", ",".join(TRAINED), "--out", str(out), *QUICK])
    return code, out


@pytest.mark.slow
def test_quick_fig3_writes_a_figure_and_a_table_with_equal_budgets(fig3):
    code, out = fig3
    assert code == 0
    png, table = out / "fig3-point.png", out / "fig3-point.csv"
    assert png.read_bytes()[:8] == PNG_MAGIC and png.stat().st_size > 20_000
    table = rows(table)
    assert {r["method"] for r in table} == set(TRAINED)
    for r in table:
        for measure in ("eval_success", "eval_success_final"):
            assert 0 <= float(r[f"{measure}_mean"]) <= 1 and float(r[f"{measure}_sem"]) >= 0
        assert r["seeds"] == "2"
    for method in TRAINED:  # the mean wall clock of each evaluation, accumulating over the run
        wall = [float(r["wall_s"]) for r in table if r["method"] == method]
        assert wall == sorted(wall) and wall[-1] > 0, (method, wall)
    last = {m: max(int(r["episodes"]) for r in table if r["method"] == m) for m in TRAINED}
    assert set(last.values()) == {160}  # 10 iterations of 16 episodes each
    assert {r["run_episodes"] for r in table} == {"160"} and {r["budget_episodes"] for r in table} == {"160"}
    # each method's members are a sweep's run dirs, one metrics file per seed
    for method in TRAINED:
        assert (out / method / "sweep.json").is_file()
        assert sorted(p.parent.name for p in (out / method).glob("s*/metrics.jsonl")) == ["s0", "s1"]
    record = json.loads((out / "figure.json").read_text())
    assert record["command"].startswith("python -m splid_jax.figures fig3")
    assert record["device"] and record["date"]


@pytest.mark.slow
def test_methods_side_by_side_learn_what_they_learn_in_turn(fig3, tmp_path):
    # one child process per method, each training its sweep as the figure in turn does (the fixture's)
    out = tmp_path / "side"
    args = ["fig3", "--methods", "gcsl,no-select", "--side-by-side", "--out", str(out), *QUICK]
    assert figures.main(args) == 0
    measures = ("episodes", "eval_success_mean", "eval_success_final_mean", "eval_return_mean")
    in_turn = {(r["method"], r["episodes"]): r for r in rows(fig3[1] / "fig3-point.csv")}
    side = rows(out / "fig3-point.csv")
    assert {r["method"] for r in side} == {"gcsl", "no-select"}
    for r in side:
        ref = in_turn[(r["method"], r["episodes"])]
        np.testing.assert_allclose([float(r[k]) for k in measures], [float(ref[k]) for k in measures], atol=1e-6)
    assert sorted(p.name for p in (out / "logs").iterdir()) == ["gcsl.log", "no-select.log"]
    assert all(run["total_s"] > 0 for run in json.loads((out / "figure.json").read_text())["runs"].values())


@pytest.mark.parametrize("args", [["fig4", "--side-by-side"], ["fig3", "--side-by-side", "--replot"]])
def test_side_by_side_is_for_training_fig3(tmp_path, capsys, args):
    assert figures.main([*args, "--out", str(tmp_path / "x"), "--quiet"]) == 2
    assert "invalid --side-by-side " in capsys.readouterr().err  # the flag as typed


@pytest.mark.slow
def test_replot_redraws_from_the_run_dirs_without_training(fig3, monkeypatch):
    code, out = fig3
    assert code == 0
    table = (out / "fig3-point.csv").read_text()
    runs = {p: p.read_bytes() for p in out.glob("*/*/metrics.jsonl")}
    (out / "fig3-point.png").unlink()
    (out / "fig3-point.csv").unlink()

    def no_training(*args, **kwargs):
        raise AssertionError("--replot trained")

    monkeypatch.setattr(loop, "run", no_training)
    assert figures.main(["fig3", "--replot", "--out", str(out), "--quiet"]) == 0
    assert (out / "fig3-point.png").read_bytes()[:8] == PNG_MAGIC
    assert (out / "fig3-point.csv").read_text() == table
    assert {p: p.read_bytes() for p in out.glob("*/*/metrics.jsonl")} == runs


@pytest.mark.slow
def test_a_figure_dir_is_never_trained_into_again(fig3, capsys):
    code, out = fig3
    assert code == 0
    before = {p: p.stat().st_mtime_ns for p in out.rglob("*") if p.is_file()}
    assert figures.main(["fig3", "--methods", "splid", "--out", str(out), *QUICK]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "invalid --out " in err and "--replot" in err
    assert {p: p.stat().st_mtime_ns for p in out.rglob("*") if p.is_file()} == before


@pytest.mark.slow
def test_resume_of_a_finished_figure_trains_nothing_and_redraws_it(fig3):
    code, out = fig3
    assert code == 0
    runs = {p: p.read_bytes() for p in out.glob("*/*/metrics.jsonl")}
    assert figures.main(["fig3", "--resume", "--out", str(out), "--quiet"]) == 0
    assert {p: p.read_bytes() for p in out.glob("*/*/metrics.jsonl")} == runs
    started = ["fig3", "--methods", ",".join(TRAINED), "--out", str(out), *QUICK]
    assert figures.main([*started, "--resume"]) == 0  # the command it was started with, resumed
    assert {p: p.read_bytes() for p in out.glob("*/*/metrics.jsonl")} == runs
    assert (out / "fig3-point.png").read_bytes()[:8] == PNG_MAGIC


def test_an_out_that_is_not_utf8_is_one_line_and_exit_2(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert figures.main(["fig8", "--quick", "--out", "bad-\udcff"]) == 2  # a \xff byte: orbax takes UTF-8 alone
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "invalid --out " in err and "UTF-8" in err
    assert list(tmp_path.iterdir()) == []


def named(field: str) -> str:
    """How an error names a setting: the flag the user typed, or the positional figure's name."""
    return "invalid FIGURE " if field == "figure" else f"invalid --{field} "


@pytest.mark.parametrize(
    "args, field",
    [
        (["fig3", "--methods", "splid,dqn"], "methods"),
        (["fig3", "--methods", "splid,splid"], "methods"),
        (["fig4", "--methods", "gcsl"], "methods"),
        (["fig3", "--set", "learning_rate=fast"], "set"),
        (["fig3", "--set", "seed=3"], "set"),
        (["fig3", "--set", "dqn.bc_steps=3"], "set"),
        (["fig3", "--set", "es.bc_steps=3"], "set"),
        (["fig3", "--values", "1,2"], "values"),
        (["fig4", "--values", "1,x"], "values"),
        (["fig4", "--values", "0,2"], "values"),  # refused as the runs' configs are built: named as typed
        (["fig5", "--values", "-1,2"], "values"),  # a leading minus is a value, not a flag
        (["fig3", "--set", "splid.sigma=-1"], "set"),
        (["fig3", "--seeds", "0"], "seeds"),
        (["fig3", "--episodes", "0"], "episodes"),
        (["fig3", "--env", "push"], "env"),
    ],
)
def test_a_bad_argument_is_one_line_and_exit_2(capsys, tmp_path, args, field):
    out = tmp_path / "out"
    assert figures.main([*args, "--quick", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and named(field) in err
    assert not out.exists()


@pytest.mark.slow
@pytest.mark.parametrize(
    "args, field",
    [
        (["fig3", "--episodes", "12800"], "episodes"),
        (["fig3", "--seeds", "3"], "seeds"),
        (["fig3", "--set", "learning_rate=0.01"], "set"),
        (["fig5"], "figure"),
        (["fig3", "--methods", "splid"], "methods"),
    ],
)
@pytest.mark.parametrize("mode", ["--resume", "--replot"])
def test_resume_and_replot_refuse_settings_the_figure_did_not_start_with(fig3, capsys, args, field, mode):
    code, out = fig3
    assert code == 0
    before = {p: p.stat().st_mtime_ns for p in out.rglob("*") if p.is_file()}
    assert figures.main([*args, mode, "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and named(field) in err
    assert {p: p.stat().st_mtime_ns for p in out.rglob("*") if p.is_file()} == before


@pytest.mark.parametrize("mode", ["--resume", "--replot"])
def test_a_dir_without_a_figure_is_blamed_on_the_flag_that_named_it(capsys, tmp_path, mode):
    assert figures.main(["fig3", mode, "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and f"invalid {mode} " in err and "figure.json" in err


def test_replot_of_a_dir_without_a_figure_is_one_line(capsys, tmp_path):
    assert figures.main(["fig3", "--replot", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "figure.json" in err


def test_help_names_every_figure_and_says_fig8_and_fig9_are_one(capsys):
    with pytest.raises(SystemExit) as exc:
        figures.main(["--help"])
    assert exc.value.code == 0
    text = " ".join(capsys.readouterr().out.split())
    assert all(f"{name}:" in text or f"{name}," in text for name in figures.SPECS)
    assert "fig8, fig9: SPLID and GCSL" in text


def test_every_method_runs_whole_chunks_nearest_the_budget(tmp_path):
    spec = figures.SPECS["fig3"]
    sets = figures.parse_sets(["eval_every=5", "num_envs=16", "gcsl.num_envs=24"], ("splid", "gcsl"))
    plans = {p.method: p for p in figures.plan(spec, "point", ("splid", "gcsl"), 3, 320, sets, str(tmp_path))}
    assert (plans["splid"].base.iterations, plans["splid"].episodes_per_iteration) == (20, 16)
    # 320 / (24 x 5) = 2.7 chunks: 3 chunks, 360 episodes, as the record says
    assert (plans["gcsl"].base.iterations, plans["gcsl"].episodes_per_iteration) == (15, 24)
    assert figures.describe(plans.values())["gcsl"]["episodes"] == 360
    assert [m.seed for m in plans["gcsl"].lanes] == [0, 1, 2]
    assert not os.path.exists(tmp_path / "splid")  # planning writes nothing
    # a tie rounds up: 400 / (32 x 5) = 2.5 chunks
    sets = figures.parse_sets(["eval_every=5", "num_envs=32"], ("splid",))
    (p,) = figures.plan(spec, "point", ("splid",), 1, 400, sets, str(tmp_path))
    assert p.base.iterations == 15


def test_fig4_is_one_sweep_over_h_and_seeds(tmp_path):
    spec = figures.SPECS["fig4"]
    (p,) = figures.plan(spec, "point", ("splid",), 2, 320, {None: {}}, str(tmp_path), quick=True)
    assert p.base.horizon == 16  # shapes for the largest H
    assert [(m.horizon, m.seed) for m in p.lanes] == [(h, s) for h in (1, 2, 4, 8, 16) for s in (0, 1)]
    assert os.path.basename(p.lanes[2].run_dir) == "H2-s0"


def test_set_reads_each_value_as_its_field_declares_it():
    sets = figures.parse_sets(
        ["hidden=32,32", "policy_ema=0.5", "gcsl.gcsl_relabel=future", "splid.normalise=false", "bc_steps=7"],
        ("splid", "gcsl"),
    )
    assert sets[None] == {"hidden": (32, 32), "policy_ema": 0.5, "bc_steps": 7}
    assert sets["gcsl"] == {"gcsl_relabel": "future"} and sets["splid"] == {"normalise": False}
    for item in ("hidden=32,x", "bc_steps=2.5", "normalise=maybe"):  # named as typed
        with pytest.raises(figures.InvalidConfig, match=f"invalid set='{item}'"):
            figures.parse_sets([item], ("splid",))


def test_a_full_disk_is_one_line_and_exit_3(tmp_path, capsys, monkeypatch):
    import errno

    def full(path, obj):
        raise OSError(errno.ENOSPC, "No space left on device", path)

    monkeypatch.setattr(loop, "write_json", full)
    assert figures.main(["fig3", "--methods", "splid", "--out", str(tmp_path / "out"), *QUICK]) == 3
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "no space left" in err and "figure.json" in err
