"""The TensorBoard writer: metrics records become scalars against episodes, read back from the event files."""

import glob
import json
import struct

import pytest

pytest.importorskip("tensorboardX")

from splid_jax import tensorboard  # noqa: E402


def read_scalars(log_dir: str) -> dict[str, list[tuple[int, float]]]:
    """Every scalar in the event files under ``log_dir``: TFRecord frames (length, crc, event, crc)."""
    from tensorboardX.proto import event_pb2

    out: dict[str, list[tuple[int, float]]] = {}
    for path in sorted(glob.glob(f"{log_dir}/events.out.tfevents.*")):
        data = open(path, "rb").read()
        pos = 0
        while pos < len(data):
            (length,) = struct.unpack("<Q", data[pos : pos + 8])
            event = event_pb2.Event.FromString(data[pos + 12 : pos + 12 + length])
            pos += 12 + length + 4
            for v in event.summary.value:
                out.setdefault(v.tag, []).append((event.step, v.simple_value))
    return out


RECORDS = [
    {"iteration": 5, "episodes": 320, "eval_success": 0.5, "eval_success_final": 0.25, "horizon": 8, "flag": True},
    {"iteration": 10, "episodes": 640, "eval_success": 0.75, "eval_success_final": 0.5, "horizon": 8, "loss": None},
]


def test_writer_writes_scalars_against_episodes(tmp_path):
    with tensorboard.MetricsWriter(str(tmp_path)) as w:
        for r in RECORDS:
            w.write(r)
    got = read_scalars(str(tmp_path))
    assert got["eval_success"] == [(320, 0.5), (640, 0.75)]
    assert got["eval_success_final"] == [(320, 0.25), (640, 0.5)]
    assert got["iteration"] == [(320, 5.0), (640, 10.0)]
    assert "episodes" not in got and "flag" not in got and "loss" not in got


def test_convert_metrics_jsonl(tmp_path):
    metrics = tmp_path / "metrics.jsonl"
    metrics.write_text("".join(json.dumps(r) + "\n" for r in RECORDS) + "\n")
    assert tensorboard.main([str(metrics), str(tmp_path / "tb")]) == 0
    assert read_scalars(str(tmp_path / "tb"))["eval_success"] == [(320, 0.5), (640, 0.75)]


def test_missing_tensorboardx_is_one_line(monkeypatch, tmp_path, capsys):
    import builtins

    real = builtins.__import__

    def fake(name, *a, **k):
        if name.startswith("tensorboardX"):
            raise ImportError(name)
        return real(name, *a, **k)

    monkeypatch.setattr(builtins, "__import__", fake)
    metrics = tmp_path / "metrics.jsonl"
    metrics.write_text(json.dumps(RECORDS[0]) + "\n")
    assert tensorboard.main([str(metrics), str(tmp_path / "tb")]) == 2
    assert "pip install" in capsys.readouterr().err


def test_train_writes_every_record_to_tensorboard(tmp_path):
    from splid_jax import train

    run_dir, log_dir = tmp_path / "run", tmp_path / "tb"
    # test_train's TINY run (two records): its program comes from the compile cache when that file ran first
    argv = ["--env", "point", "--iterations", "10", "--num-envs", "8", "--eval-episodes", "16", "--bc-steps", "40",
            "--batch-size", "64", "--hidden", "32,32", "--eval-every", "5"]  # fmt: skip
    argv += ["--run-dir", str(run_dir), "--quiet", "--compile-cache", "", "--tensorboard", str(log_dir)]
    assert train.main(argv) == 0
    records = [json.loads(line) for line in (run_dir / "metrics.jsonl").read_text().splitlines()]
    seen = read_scalars(str(log_dir))
    assert [step for step, _ in seen["eval_success_final"]] == [r["episodes"] for r in records]
    assert [v for _, v in seen["eval_success"]] == pytest.approx([r["eval_success"] for r in records])


def test_sweep_writes_each_member_under_its_own_name(tmp_path):
    from splid_jax import sweep

    run_dir, log_dir = tmp_path / "sweep", tmp_path / "tb"
    # test_sweep's resumed sweep at its sizes (two members, two records each), so its program may come from the cache
    argv = ["--env", "point", "--num-envs", "4", "--eval-episodes", "8", "--eval-every", "2", "--bc-steps", "5",
            "--batch-size", "16", "--hidden", "16", "--seeds", "2", "--horizons", "4", "--iterations", "4"]  # fmt: skip
    argv += ["--run-dir", str(run_dir), "--quiet", "--no-plot", "--compile-cache", ""]
    assert sweep.main([*argv, "--tensorboard", str(log_dir)]) == 0
    for member in sorted(p.name for p in run_dir.iterdir() if (p / "metrics.jsonl").is_file()):
        records = [json.loads(line) for line in (run_dir / member / "metrics.jsonl").read_text().splitlines()]
        seen = read_scalars(str(log_dir / member))
        assert [v for _, v in seen["eval_success_final"]] == pytest.approx([r["eval_success_final"] for r in records])


def test_a_missing_extra_is_one_line_before_any_work(tmp_path, monkeypatch, capsys):
    import builtins

    from splid_jax import train

    real_import = builtins.__import__

    def no_tensorboardx(name, *args, **kwargs):
        if name == "tensorboardX":
            raise ImportError(name)
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_tensorboardx)
    run_dir = tmp_path / "run"
    argv = ["--env", "point", "--iterations", "5", "--run-dir", str(run_dir), "--tensorboard", str(tmp_path / "tb")]
    assert train.main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "tensorboardX" in err and "tensorboard" in err
    assert not (run_dir / "metrics.jsonl").exists()


@pytest.mark.parametrize("command", ["train", "sweep"])
@pytest.mark.parametrize("where", ["a-file", "/proc/splid-tb"])
def test_a_tensorboard_dir_that_cannot_be_written_is_refused_before_any_work(tmp_path, capsys, command, where):
    import importlib

    (tmp_path / "a-file").write_text("x")
    log_dir = where if where.startswith("/") else str(tmp_path / where)
    argv = ["--env", "point", "--iterations", "5", "--run-dir", str(tmp_path / "run"), "--tensorboard", log_dir]
    assert importlib.import_module(f"splid_jax.{command}").main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "invalid --tensorboard " in err and "writable" in err
    assert not (tmp_path / "run").exists()


def test_a_full_disk_fails_the_write_itself_and_the_close_after_it_is_quiet(tmp_path, monkeypatch):
    import errno
    import socket
    import time

    monkeypatch.setattr(time, "time", lambda: 1234567890.5)  # the event file's name, made ahead as /dev/full
    (tmp_path / f"events.out.tfevents.1234567890.{socket.gethostname()}").symlink_to("/dev/full")
    with pytest.raises(OSError) as failed, tensorboard.recording(str(tmp_path)) as on_record:
        on_record(str(tmp_path / "run"), RECORDS[0])
    assert failed.value.errno == errno.ENOSPC


@pytest.mark.parametrize(
    "content, said",
    [
        (b'{"iteration": 5, "episodes": 1}\n\xff\xfe\n', "metrics.jsonl:2: not UTF-8 text"),
        (b'{"iteration": 5, "episodes": 1}\n[1, 2]\n', "metrics.jsonl:2: not a metrics record"),
        (b'{"iteration": 5, "episodes": 1}\nnot json\n{"iteration": 10}\n', "metrics.jsonl:2: not a JSON record"),
        (b'{"iteration": 5, "episodes": "many"}\n', "non-numeric episodes"),
    ],
)
def test_a_garbage_metrics_line_is_one_line_naming_it(tmp_path, capsys, content, said):
    metrics = tmp_path / "metrics.jsonl"
    metrics.write_bytes(content)
    assert tensorboard.main([str(metrics), str(tmp_path / "tb")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and said in err


def test_a_torn_last_line_is_dropped(tmp_path, capsys):
    metrics = tmp_path / "metrics.jsonl"
    metrics.write_text(json.dumps(RECORDS[0]) + "\n" + json.dumps(RECORDS[1])[:20])
    assert tensorboard.main([str(metrics), str(tmp_path / "tb")]) == 0
    assert "1 records" in capsys.readouterr().out


@pytest.mark.parametrize("argv", [[], ["a.jsonl", "out", "extra"], ["--bogus", "a.jsonl", "out"]])
def test_a_bad_command_line_is_one_line_pointing_at_help(capsys, argv):
    with pytest.raises(SystemExit) as stop:
        tensorboard.main(argv)
    err = capsys.readouterr().err
    assert stop.value.code == 2 and len(err.splitlines()) == 1 and "--help" in err, err
