"""A figure directory read back as the command leaves it, from made-up runs: the series, their legend and
seconds, and figures trained apart merged into one and resumed part by part."""

import csv
import json
import os
from pathlib import Path

import numpy as np
import pytest

from splid_jax import figures
from splid_jax.figures import cli as figure_cli
from splid_jax.figures import runs as figure_runs
from splid_jax.runtime import loop

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
QUICK = ["--quick", "--seeds", "2", "--episodes", "160", "--set", "eval_episodes=20", "--quiet"]


def rows(path: Path) -> list[dict]:
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def fake_run(run_dir: Path, config: dict, success: list[float]):
    run_dir.mkdir(parents=True)
    (run_dir / "config.json").write_text(json.dumps(config))
    with open(run_dir / "metrics.jsonl", "w") as fh:
        for i, s in enumerate(success, 1):
            rec = dict(iteration=5 * i, episodes=80 * i, env_steps=4000 * i, select_steps=0, eval_success=s,
                       eval_success_final=s / 2, eval_return=10 * s, wall_s=float(i))  # fmt: skip
            fh.write(json.dumps(rec) + "\n")


def fake_figure(out: Path, figure: str, methods: dict[str, list[tuple[dict, list[float]]]]) -> dict:
    """A figure dir as the command leaves it, with made-up metrics."""
    runs = {}
    for method, members in methods.items():
        names = []
        for config, success in members:
            name = f"{figures.member_name(config['seed'], figures.SPECS[figure].vary, config.get('horizon'))}"
            fake_run(out / method / name, config, success)
            names.append({**config, "run_dir": name})
        runs[method] = {"iterations": 10, "episodes_per_iteration": 16, "episodes": 160, "members": names}
    record = dict(figure=figure, env="point", methods=list(methods), seeds=2, budget_episodes=160, device="CPU",
                  date="2026-11-23", command="python -m splid_jax.figures", runs=runs)  # fmt: skip
    (out / figures.SPEC).write_text(json.dumps(record))
    return record


def test_mean_and_standard_error_over_seeds(tmp_path):
    fake_figure(tmp_path, "fig6", {
        "splid": [({"seed": 0, "algo": "splid"}, [0.2, 0.6]), ({"seed": 1, "algo": "splid"}, [0.4, 1.0])],
        "no-select": [({"seed": 0, "algo": "splid", "select": False}, [0.1, 0.3])],
    })  # fmt: skip
    png, table = figures.render(str(tmp_path), quiet=True)
    table = rows(Path(table))
    splid = [r for r in table if r["method"] == "splid"]
    assert [float(r["eval_return_mean"]) for r in splid] == pytest.approx([3.0, 8.0])
    assert [float(r["eval_return_sem"]) for r in splid] == pytest.approx([1.0, 2.0])  # std (ddof 1) / sqrt(2)
    assert [r["eval_return_sem"] for r in table if r["method"] == "no-select"] == ["", ""]  # one seed: none
    assert Path(png).read_bytes()[:8] == PNG_MAGIC


def test_a_method_stopped_before_its_iterations_says_where_in_the_legend(tmp_path):
    fake_figure(tmp_path, "fig6", {
        "splid": [({"seed": 0, "algo": "splid", "iterations": 10}, [0.2, 0.6])],
        "no-select": [({"seed": 0, "algo": "splid", "select": False, "iterations": 20}, [0.1, 0.3])],
    })  # fmt: skip
    record = json.loads((tmp_path / figures.SPEC).read_text())
    fig = figures.draw(record, figures.load_series(str(tmp_path), record))
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    assert labels == ["SPLID (1 seed)", "SPLID without SELECT, stopped at 160 episodes (1 seed)"]


def test_fig4_draws_one_series_per_h(tmp_path):
    members = [({"seed": s, "algo": "splid", "horizon": h}, list(np.linspace(0.1, h / 8, 3))) for h in (2, 8)
               for s in (0, 1)]  # fmt: skip
    fake_figure(tmp_path, "fig4", {"splid": members})
    _, table = figures.render(str(tmp_path), quiet=True)
    table = rows(Path(table))
    assert sorted({r["horizon"] for r in table}) == ["2", "8"]
    assert all(r["seeds"] == "2" for r in table)
    assert float([r for r in table if r["horizon"] == "8"][-1]["eval_success_mean"]) == pytest.approx(1.0)


def test_pchid_reaches_its_full_horizon_half_way_through_the_figure_run(tmp_path):
    spec = figures.SPECS["fig3"]
    sets = figures.parse_sets(["num_envs=16"], ("pchid",))
    (p,) = figures.plan(spec, "point", ("pchid",), 1, 16 * 40 * 4, sets, str(tmp_path))
    assert p.base.pchid_every == max(1, p.base.iterations // (2 * p.base.horizon))
    assert all(lane.pchid_every == p.base.pchid_every for lane in p.lanes)


@pytest.mark.parametrize("figure", ["fig8", "fig9"])
def test_fig8_and_fig9_draw_return_and_both_success_measures_of_splid_and_gcsl(tmp_path, figure):
    assert figures.SPECS[figure].methods == ("splid", "gcsl")
    fake_figure(tmp_path, figure, {
        "splid": [({"seed": 0, "algo": "splid"}, [0.2, 0.6]), ({"seed": 1, "algo": "splid"}, [0.4, 1.0])],
        "gcsl": [({"seed": 0, "algo": "gcsl", "gcsl_relabel": "final"}, [0.1, 0.3])],
    })  # fmt: skip
    png, table = figures.render(str(tmp_path), quiet=True)
    table = rows(Path(table))
    splid = [r for r in table if r["method"] == "splid"]
    assert [float(r["eval_return_mean"]) for r in splid] == pytest.approx([3.0, 8.0])
    assert [float(r["eval_success_final_mean"]) for r in splid] == pytest.approx([0.15, 0.4])
    assert Path(png).name == f"{figure}-point.png" and Path(png).read_bytes()[:8] == PNG_MAGIC
    record = figures.load_record(str(tmp_path))
    fig = figures.draw(record, figures.load_series(str(tmp_path), record))
    return_axis, any_axis, final_axis = fig.axes
    assert return_axis.get_ylabel() == "average return" and any_axis.get_ylabel() == "evaluation success rate"
    assert return_axis.get_ylim()[1] > 7  # its own scale, not the success panels' [0, 1]
    assert final_axis.get_ylim() == any_axis.get_ylim()
    assert fig._suptitle.get_text().startswith("Figures 8 and 9: SPLID against GCSL on point")


def test_a_stopped_method_keeps_its_seconds_for_the_resumed_total(tmp_path, monkeypatch):
    """A figure trained over several calls reports each method's time over all of them."""
    out = tmp_path / "out"
    calls, clock = [], [1000.0]

    def stopped(*args, **kwargs):  # each call trains 2.5 s on the clock the figure reads
        calls.append(kwargs.get("resume"))
        clock[0] += 2.5
        raise loop.Interrupted(15)

    monkeypatch.setattr(loop, "run", stopped)
    monkeypatch.setattr(figure_runs.time, "perf_counter", lambda: clock[0])
    assert figures.main(["fig3", "--methods", "gcsl", "--out", str(out), *QUICK]) == 143
    assert json.loads((out / "figure.json").read_text())["runs"]["gcsl"]["total_s"] == 2.5
    assert figures.main(["fig3", "--resume", "--out", str(out), "--quiet"]) == 143
    assert json.loads((out / "figure.json").read_text())["runs"]["gcsl"]["total_s"] == 5.0  # both calls' seconds
    assert calls == [False, False]  # nothing was saved, so the second call starts the method afresh


def test_members_without_their_config_json_replot_the_same_from_the_figures_record(tmp_path):
    from splid_jax.config import TrainConfig

    her = {**TrainConfig(env="push", algo="her").to_json(), "seed": 0}
    fake_figure(tmp_path, "fig3", {
        "her": [(her, [0.2, 0.4])],
        "gcsl": [({"seed": 0, "algo": "gcsl", "gcsl_relabel": "final"}, [0.1, 0.3])],
    })  # fmt: skip
    def legend():
        return [(s.label, s.columns["episodes"].tolist()) for s in figures.load_series(str(tmp_path), record)]

    record = figures.load_record(str(tmp_path))
    before = legend()
    for path in tmp_path.rglob("config.json"):
        path.unlink()
    after = legend()
    assert after == before and before[0][0].startswith("HER (mrl)") and "final-state" in before[1][0]


def test_merge_joins_subsets_trained_apart_into_one_figure(tmp_path, capsys):
    a, b, out = tmp_path / "a", tmp_path / "b", tmp_path / "out"
    fake_figure(a, "fig3", {"her": [({"seed": 0, "algo": "her"}, [0.2, 0.4])]})
    fake_figure(b, "fig3", {
        "splid": [({"seed": 0, "algo": "splid"}, [0.5, 0.9])],
        "her-baselines": [({"seed": 0, "algo": "her", "preset": "paper"}, [0.1, 0.2])],
        "gcsl": [({"seed": 0, "algo": "gcsl", "gcsl_relabel": "final"}, [0.1, 0.1])],
    })  # fmt: skip
    (a / "her" / "s0" / "checkpoints").mkdir()
    before = {p: p.read_bytes() for p in tmp_path.rglob("*") if p.is_file()}
    assert figures.main(["fig3", "--merge", str(a), str(b), "--out", str(out), "--quiet"]) == 0
    assert {p: p.read_bytes() for p in tmp_path.rglob("*") if p.is_file() and out not in p.parents} == before
    record = json.loads((out / "figure.json").read_text())
    assert record["methods"] == ["splid", "gcsl", "her", "her-baselines"]  # the figure's legend order
    assert set(record["runs"]) == {"splid", "gcsl", "her", "her-baselines"} and len(record["parts"]) == 2
    assert record["command"].startswith("python -m splid_jax.figures fig3 --merge")
    assert (out / "her" / "s0" / "checkpoints").is_dir()  # --resume continues an unfinished part
    assert {r["method"] for r in rows(out / "fig3-point.csv")} == {"splid", "gcsl", "her", "her-baselines"}


def test_merge_replaces_a_method_of_an_earlier_merged_figure_and_keeps_each_runs_command(tmp_path, capsys):
    a, b, c, first, out = (tmp_path / n for n in ("a", "b", "c", "first", "out"))
    fake_figure(a, "fig3", {"her": [({"seed": 0, "algo": "her"}, [0.2, 0.4])]})
    fake_figure(b, "fig3", {"splid": [({"seed": 0, "algo": "splid"}, [0.5, 0.6])]})
    record = fake_figure(c, "fig3", {"splid": [({"seed": 0, "algo": "splid"}, [0.7, 0.9])]})
    (c / figures.SPEC).write_text(json.dumps({**record, "command": "the rerun", "device": "GPU", "date": "2026-11-27"}))
    assert figures.main(["fig3", "--merge", str(a), str(b), "--out", str(first), "--quiet"]) == 0
    # a method in two parts is refused unless the last part's run is asked for
    assert figures.main(["fig3", "--merge", str(first), str(c), "--out", str(out), "--quiet"]) == 2
    assert "--replace" in capsys.readouterr().err and not out.exists()
    assert figures.main(["fig3", "--merge", str(first), str(c), "--out", str(out), "--quiet", "--replace"]) == 0
    merged = json.loads((out / "figure.json").read_text())
    assert merged["methods"] == ["splid", "her"]
    assert [(p["command"], p["methods"]) for p in merged["parts"]] == [
        ("python -m splid_jax.figures", ["her"]),  # the first merge's own part, not the first merge's command
        ("the rerun", ["splid"]),
    ]
    assert merged["device"] == "CPU + GPU" and merged["date"] == "2026-11-23 + 2026-11-27"
    splid = {r["episodes"]: r for r in rows(out / "fig3-point.csv") if r["method"] == "splid"}
    assert [float(splid[k]["eval_success_mean"]) for k in sorted(splid, key=int)] == pytest.approx([0.7, 0.9])


def test_replace_without_merge_is_refused_in_one_line(tmp_path, capsys):
    assert figures.main(["fig3", "--replace", "--out", str(tmp_path / "out"), "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "invalid --replace " in err


@pytest.mark.parametrize("clash", ["method", "budget", "figure"])
def test_merge_refuses_parts_that_are_not_one_figure(tmp_path, capsys, clash):
    a, b, out = tmp_path / "a", tmp_path / "b", tmp_path / "out"
    fake_figure(a, "fig3", {"splid": [({"seed": 0, "algo": "splid"}, [0.5])]})
    other = "splid" if clash == "method" else "gcsl"
    record = fake_figure(b, "fig3", {other: [({"seed": 0, "algo": other}, [0.5])]})
    if clash == "budget":
        (b / "figure.json").write_text(json.dumps({**record, "budget_episodes": 320}))
    args = ["fig6" if clash == "figure" else "fig3", "--merge", str(a), str(b), "--out", str(out)]
    assert figures.main(args) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "invalid --merge " in err
    assert not out.exists()


def test_merge_joins_values_trained_apart_into_one_figure(tmp_path):
    """Figure 4's values trained as parts of their own shapes draw as the one-sweep figure does."""
    a, b, out = tmp_path / "a", tmp_path / "b", tmp_path / "out"
    member = lambda s, h: ({"seed": s, "algo": "splid", "horizon": h}, [0.1, h / 16])  # noqa: E731
    fake_figure(a, "fig4", {"splid": [member(s, 16) for s in (0, 1)]})
    fake_figure(b, "fig4", {"splid": [member(s, h) for h in (2, 8) for s in (0, 1)]})
    (a / "splid" / "checkpoints").mkdir()
    before = {p: p.read_bytes() for p in tmp_path.rglob("*") if p.is_file()}
    assert figures.main(["fig4", "--merge", str(a), str(b), "--out", str(out), "--quiet"]) == 0
    assert {p: p.read_bytes() for p in tmp_path.rglob("*") if p.is_file() and out not in p.parents} == before
    record = json.loads((out / "figure.json").read_text())
    assert record["methods"] == ["splid"] and [p["dir"] for p in record["runs"]["splid"]["parts"]] == ["part0", "part1"]
    assert (out / "splid" / "part0" / "checkpoints").is_dir()  # each part resumes in its own directory
    table = rows(out / "fig4-point.csv")
    assert sorted({int(r["horizon"]) for r in table}) == [2, 8, 16] and {r["seeds"] for r in table} == {"2"}
    last = {int(r["horizon"]): float(r["eval_success_mean"]) for r in table if r["iteration"] == "10"}
    assert last == pytest.approx({2: 2 / 16, 8: 8 / 16, 16: 1.0})


def test_merge_refuses_a_value_in_two_parts(tmp_path, capsys):
    a, b, out = tmp_path / "a", tmp_path / "b", tmp_path / "out"
    fake_figure(a, "fig4", {"splid": [({"seed": 0, "algo": "splid", "horizon": 8}, [0.5])]})
    fake_figure(b, "fig4", {"splid": [({"seed": 0, "algo": "splid", "horizon": h}, [0.5]) for h in (4, 8)]})
    assert figures.main(["fig4", "--merge", str(a), str(b), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "distinct H values" in err
    assert not out.exists()


def test_a_merged_sweep_resumes_each_part_with_its_own_shapes(tmp_path, monkeypatch):
    calls = []

    def run(base, env, members, resume, quiet):
        calls.append((base.run_dir, base.horizon, sorted({m.horizon for m in members}), len(members)))
        for m in members:
            assert m.run_dir.startswith(base.run_dir + os.sep)
            if not os.path.isdir(m.run_dir):
                fake_run(Path(m.run_dir), {"seed": m.seed, "algo": "splid", "horizon": m.horizon}, [0.5])

    monkeypatch.setattr(loop, "run", run)
    parts = [tmp_path / "h16", tmp_path / "h2-4"]
    for part, values in zip(parts, ("16", "2,4"), strict=True):
        assert figures.main(["fig4", "--values", values, "--out", str(part), *QUICK]) == 0
    calls.clear()
    out = tmp_path / "out"
    assert figures.main(["fig4", "--merge", *map(str, parts), "--out", str(out), "--quiet"]) == 0
    assert figures.main(["fig4", "--resume", "--out", str(out), "--quiet"]) == 0
    assert calls == [(str(out / "splid" / "part0"), 16, [16], 2), (str(out / "splid" / "part1"), 4, [2, 4], 4)]


@pytest.mark.parametrize("started", [["--side-by-side"], []])
def test_a_figure_resumes_side_by_side_only_if_it_was_started_so(tmp_path, monkeypatch, started):
    out, trained = tmp_path / "out", []

    def stopped(*args, **kwargs):
        raise loop.Interrupted(15)

    def trains(how):
        def train(out, record, quiet, resume=False):
            trained.append((how, resume))
            figure_runs.train(out, record, quiet, resume=resume)  # writes the record, then stops

        return train

    monkeypatch.setattr(loop, "run", stopped)
    monkeypatch.setattr(figure_cli, "train", trains("in turn"))
    monkeypatch.setattr(figure_cli, "train_side_by_side", trains("side by side"))
    assert figures.main(["fig3", "--methods", "gcsl", *started, "--out", str(out), *QUICK]) == 143
    assert figures.main(["fig3", "--resume", "--out", str(out), "--quiet"]) == 143
    how = "side by side" if started else "in turn"
    assert trained == [(how, False), (how, True)]
