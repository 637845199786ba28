import json
import os
from pathlib import Path

import numpy as np
import pytest

from splid_jax import plot

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def make_run(root: Path, name: str, seed: int, select: bool = True, n: int = 12, **config) -> Path:
    run = root / name
    run.mkdir(parents=True)
    (run / "config.json").write_text(json.dumps({"env": "point", "select": select, "seed": seed, **config}))
    rng = np.random.default_rng(seed)
    with open(run / "metrics.jsonl", "w") as fh:
        for i in range(1, n + 1):
            success = min(1.0, i / n + 0.1 * rng.random())
            rec = {
                "iteration": 10 * i,
                "episodes": 640 * i,
                "env_steps": 640 * 50 * i,
                "select_steps": (3000 * i) if select else 0,
                "eval_success": success,
                "eval_success_final": 0.8 * success,
                "eval_return": -50 + 40 * success,
                "wall_s": 2.0 * i + rng.random(),
                "bc_loss": 0.1,
            }
            fh.write(json.dumps(rec) + "\n")
    return run


def assert_png(path: Path):
    assert path.is_file()
    assert path.read_bytes()[:8] == PNG_MAGIC
    assert path.stat().st_size > 20_000  # six panels with curves, not an empty canvas


def test_two_runs_default_output(tmp_path, capsys):
    a = make_run(tmp_path, "point-s0", 0)
    b = make_run(tmp_path, "point-nosel-s1", 1, select=False)
    assert plot.main([str(a), str(b), "--smooth", "3"]) == 0
    assert_png(a / "curves.png")
    assert capsys.readouterr().out.strip() == str(a / "curves.png")


def test_each_panel_plots_the_runs_smoothed_measures_against_its_axis(tmp_path):
    runs = [plot.load_run(make_run(tmp_path, "a", 0)), plot.load_run(make_run(tmp_path, "b", 1, select=False))]
    fig = plot.figure(runs, k=3)
    panels = fig.axes[:6]  # rows: success, return; columns: episodes, env steps, wall clock
    for col, x_key in enumerate(("episodes", "env_steps", "wall_s")):
        success, ret = panels[col], panels[3 + col]
        for i, run in enumerate(runs):
            any_step, final_step = success.get_lines()[2 * i : 2 * i + 2]
            (returns,) = ret.get_lines()[i : i + 1]
            for line in (any_step, final_step, returns):
                np.testing.assert_array_equal(line.get_xdata(), run.columns[x_key])
            np.testing.assert_allclose(any_step.get_ydata(), plot.smooth(run.columns["eval_success"], 3))
            np.testing.assert_allclose(final_step.get_ydata(), plot.smooth(run.columns["eval_success_final"], 3))
            np.testing.assert_allclose(returns.get_ydata(), plot.smooth(run.columns["eval_return"], 3))
            assert any_step.get_linestyle() == "-" and final_step.get_linestyle() == "--"


def test_group_and_out(tmp_path):
    dirs = [make_run(tmp_path, f"s{s}", s, sigma=0.5) for s in range(3)]
    dirs += [make_run(tmp_path, f"h{s}", s, sigma=1.0, n=10) for s in range(2)]
    out = tmp_path / "figs" / "sweep.png"
    assert plot.main([*map(str, dirs), "--group", "--out", str(out)]) == 0
    assert_png(out)


def test_an_existing_out_is_kept_unless_overwrite_is_given(tmp_path, capsys):
    run = make_run(tmp_path, "s0", 0)
    out = tmp_path / "mine.png"
    out.write_bytes(b"the user's figure")
    assert plot.main([str(run), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "--overwrite" in err and out.read_bytes() == b"the user's figure"
    assert plot.main([str(run), "--out", str(out), "--overwrite"]) == 0
    assert_png(out)


def test_labels_and_groups(tmp_path):
    runs = [
        plot.load_run(make_run(tmp_path, "a", 0, sigma=0.5, horizon=8)),
        plot.load_run(make_run(tmp_path, "b", 1, sigma=0.5, horizon=8)),
        plot.load_run(make_run(tmp_path, "c", 0, select=False, sigma=1.0, horizon=8)),
    ]
    (tmp_path / "bare").mkdir()
    (tmp_path / "bare" / "metrics.jsonl").write_text((tmp_path / "a" / "metrics.jsonl").read_text())
    runs.append(plot.load_run(tmp_path / "bare"))
    full, group = plot.labels(runs)
    assert full == ["point select sigma=0.5 s0", "point select sigma=0.5 s1", "point no-select sigma=1.0 s0", "bare"]
    assert group[0] == group[1] != group[2]


def test_a_learner_without_select_is_not_labelled_select(tmp_path):
    runs = [plot.load_run(make_run(tmp_path, name, 0, algo=name)) for name in ("her", "splid")]
    assert plot.labels(runs)[0] == ["point algo=her s0", "point select algo=splid s0"]


def test_labels_leave_out_the_device_and_read_a_later_setting_as_runs_before_it_behaved(tmp_path):
    gpu = lambda kind: {"devices": {"kind": kind, "count": 1}}  # noqa: E731
    runs = [
        plot.load_run(make_run(tmp_path, "before", 0, **gpu("H200"))),  # recorded before buffer_window existed
        plot.load_run(make_run(tmp_path, "whole", 1, buffer_window=0, **gpu("H100"))),
        plot.load_run(make_run(tmp_path, "window", 2, buffer_window=50, **gpu("H100"))),
    ]
    assert plot.labels(runs)[0] == [
        "point select buffer_window=0 s0",
        "point select buffer_window=0 s1",
        "point select buffer_window=50 s2",
    ]


def test_an_unreadable_metrics_file_is_not_called_missing(tmp_path, monkeypatch, capsys):
    run = make_run(tmp_path, "a", 0)
    real_access = os.access  # permissions that bar even root, as a read-only share does for others
    monkeypatch.setattr(os, "access", lambda p, m: not str(p).endswith("metrics.jsonl") and real_access(p, m))
    assert plot.main([str(run), "--out", str(tmp_path / "x.png")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "cannot be read (Permission denied)" in err


def test_group_mean_and_band(tmp_path):
    dirs = [make_run(tmp_path, f"s{s}", s, n=8 + s) for s in range(3)]  # unequal lengths: common evals only
    runs = [plot.load_run(d) for d in dirs]
    (curve,) = plot._curves(runs, k=1, group=True)
    ys = np.stack([r.columns["eval_success"][:8] for r in runs])
    assert len(curve.columns["eval_success"]) == 8
    np.testing.assert_allclose(curve.columns["eval_success"], ys.mean(0))
    np.testing.assert_allclose(curve.low["eval_success"], ys.min(0))
    np.testing.assert_allclose(curve.high["eval_success"], ys.max(0))


def test_smooth_is_trailing_mean():
    np.testing.assert_allclose(plot.smooth(np.array([0.0, 3.0, 6.0, 9.0]), 2), [0.0, 1.5, 4.5, 7.5])
    np.testing.assert_allclose(plot.smooth(np.array([1.0, 2.0]), 1), [1.0, 2.0])


def test_truncated_last_line_is_ignored(tmp_path):
    run = make_run(tmp_path, "r", 0, n=5)
    with open(run / "metrics.jsonl", "a") as fh:
        fh.write('{"iteration": 60, "episo')
    assert len(plot.load_run(run).columns["iteration"]) == 5


@pytest.mark.parametrize(
    "setup, message",
    [
        (lambda root: root / "nope", "no such run directory"),
        (lambda root: root.joinpath("empty_dir").mkdir() or root / "empty_dir", "no metrics file"),
        (lambda root: _with_metrics(root, ""), "no evaluation records"),
        (lambda root: _with_metrics(root, '{"iteration": 1}\n'), "record 1 lacks episodes"),
        (lambda root: _with_metrics(root, "garbage\n{}\n"), "metrics.jsonl:1: not a JSON record"),
    ],
    ids=["missing-dir", "missing-metrics", "empty-metrics", "missing-key", "bad-line"],
)
def test_errors_exit_2(tmp_path, capsys, setup, message):
    good = make_run(tmp_path, "good", 0)
    bad = setup(tmp_path)
    assert plot.main([str(good), str(bad)]) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1
    assert not (good / "curves.png").exists()


def _with_metrics(root: Path, text: str) -> Path:
    run = root / "bad"
    run.mkdir()
    (run / "metrics.jsonl").write_text(text)
    return run


def test_bad_arguments_exit_2(tmp_path):
    assert plot.main([str(make_run(tmp_path, "r", 0)), "--smooth", "0"]) == 2
    assert plot.main([]) == 2


def _drawn_pixels(fig, rgb) -> list[int]:
    """Per panel, the pixels drawn within 10 levels of colour ``rgb``."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    image = np.asarray(canvas.buffer_rgba())[::-1, :, :3].astype(int)  # row 0 at the bottom, as bboxes count
    near = (np.abs(image - np.asarray(rgb)) <= 10).all(axis=-1)
    counts = []
    for ax in fig.axes:
        b = ax.get_window_extent()
        counts.append(int(near[int(b.y0) : int(b.y1), int(b.x0) : int(b.x1)].sum()))
    return counts


def test_a_run_with_one_evaluation_draws_a_point_in_every_panel(tmp_path):
    run = plot.load_run(make_run(tmp_path, "r", 0, n=1))
    tab_blue = (31, 119, 180)
    assert min(_drawn_pixels(plot.figure([run]), tab_blue)) > 20


def test_figure_has_a_title_and_a_legend_of_both_success_measures(tmp_path):
    runs = [plot.load_run(make_run(tmp_path, f"s{s}", s)) for s in range(2)]
    fig = plot.figure(runs, k=3, group=True)
    title = fig.get_suptitle()
    assert title.startswith("point: evaluation of 2 runs") and "min-max band" in title and "over 3" in title
    (legend,) = fig.legends
    names = [t.get_text() for t in legend.get_texts()]
    assert names[-2:] == ["success at any step", "success at the final step"]
    assert plot.figure(runs[:1]).get_suptitle() == "point: evaluation of 1 run"


def test_help_is_plain_text_and_abbreviations_are_refused(tmp_path, capsys):
    assert "``" not in plot.build_parser().format_help()
    assert plot.main([str(make_run(tmp_path, "r", 0)), "--smoo", "3"]) == 2
    assert "unrecognized arguments: --smoo" in capsys.readouterr().err


def test_out_that_is_not_an_image_is_refused(tmp_path, capsys):
    run = make_run(tmp_path, "r", 0)
    assert plot.main([str(run), "--out", str(run / "metrics.jsonl")]) == 2
    assert capsys.readouterr().err.count("\n") == 1
    assert (run / "metrics.jsonl").read_text().count("\n") == 12


def test_an_error_line_is_in_the_commands_style(tmp_path, capsys):
    assert plot.main([str(tmp_path / "absent")]) == 2
    assert capsys.readouterr().err.startswith("python -m splid_jax.plot: error: ")
