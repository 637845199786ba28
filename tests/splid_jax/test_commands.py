"""What every command shares: one line, never a traceback, for a bad environment variable and for a
signal outside a run's own handlers (before it, after it, in a command that trains nothing). In
subprocesses, since the variables and signals are the process's own."""

import os
import subprocess
import sys

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def python(code: str, *args: str, env: dict | None = None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", code, *args], capture_output=True, text=True, timeout=120,
                          env={**os.environ, **(env or {})}, cwd=ROOT)  # fmt: skip


@pytest.mark.slow
@pytest.mark.parametrize("variable", ["MUJOCO_GL", "JAX_PLATFORMS"])
def test_a_bad_environment_variable_is_one_line_naming_it(tmp_path, variable):
    run = "import runpy; runpy.run_module('splid_jax.train', run_name='__main__', alter_sys=True)"
    done = python(run, "--env", "point", "--run-dir", str(tmp_path / "run"), env={variable: "bogus"})
    assert done.returncode == 2, done.stderr
    assert len(done.stderr.strip().splitlines()) == 1 and f"{variable}='bogus'" in done.stderr
    assert not (tmp_path / "run").exists()


def test_a_signal_after_the_run_says_the_run_is_whole():
    done = python("import os, signal, time\nfrom splid_jax import cli\ncli.quiet_interrupts()\n"
                  "cli.interrupts_now('after the run completed (R is whole)')\n"
                  "os.kill(os.getpid(), signal.SIGINT)\ntime.sleep(10)")  # fmt: skip
    assert done.returncode == 130 and done.stderr == "interrupted (SIGINT) after the run completed (R is whole)\n"


def test_a_signal_while_python_shuts_down_after_the_work_is_ignored():
    done = python("import atexit, os, signal, time\nfrom splid_jax import cli\ncli.quiet_interrupts()\n"
                  "atexit.register(lambda: (os.kill(os.getpid(), signal.SIGTERM), time.sleep(0.2)))\n"
                  "cli.exit_with(0)")  # fmt: skip
    assert done.returncode == 0 and done.stderr == ""


@pytest.mark.slow
@pytest.mark.parametrize("command", ["plot", "rollout"])
def test_ctrl_c_in_a_command_that_trains_nothing_is_one_line(tmp_path, command):
    stops_at_parse = ("import argparse, os, runpy, signal, sys, time\n"
                      "def parse(*a, **k):\n    os.kill(os.getpid(), signal.SIGINT)\n    time.sleep(10)\n"
                      "argparse.ArgumentParser.parse_args = parse\n"
                      f"runpy.run_module('splid_jax.{command}', run_name='__main__', alter_sys=True)")  # fmt: skip
    done = python(stops_at_parse, str(tmp_path))
    assert done.returncode == 130 and done.stderr == "interrupted (SIGINT)\n", done.stderr


@pytest.mark.parametrize("under", ["", "sub"], ids=["a-file", "under-a-file"])
def test_a_compile_cache_that_is_a_file_is_one_line_before_any_work(tmp_path, capsys, under):
    from splid_jax import train

    (tmp_path / "taken").write_text("kept")
    cache = tmp_path / "taken" / under if under else tmp_path / "taken"
    with pytest.raises(SystemExit) as stop:
        train.main(["--env", "point", "--compile-cache", str(cache), "--run-dir", str(tmp_path / "run")])
    err = capsys.readouterr().err
    assert stop.value.code == 2 and len(err.splitlines()) == 1 and "argument --compile-cache: " in err, err
    assert (tmp_path / "taken").read_text() == "kept" and not (tmp_path / "run").exists()


@pytest.mark.skipif(not os.path.isdir("/proc/self"), reason="needs Linux's /proc, where no directory can be made")
def test_an_unwritable_compile_cache_is_one_line_and_the_default_is_turned_off(tmp_path, capsys, monkeypatch):
    from splid_jax import cli, train

    with pytest.raises(SystemExit) as stop:
        train.main(["--env", "point", "--compile-cache", "/proc/splid_jax_cache", "--run-dir", str(tmp_path / "run")])
    err = capsys.readouterr().err
    assert stop.value.code == 2 and len(err.splitlines()) == 1 and "cannot be written" in err, err
    assert not (tmp_path / "run").exists()
    monkeypatch.setenv("XDG_CACHE_HOME", "/proc/splid_jax_home")  # the default's parent
    parser = cli.Parser()
    cli.add_compile_cache_flag(parser)
    assert parser.parse_args([]).compile_cache == ""
    assert "compiling without it" in capsys.readouterr().err


@pytest.mark.parametrize("args, said", [(["--hidden", "-5,4"], "invalid --hidden -5,4: must be one or more widths"),
                                        (["--sigma", "-1e-3"], "invalid --sigma -0.001: must be >= 0")])  # fmt: skip
def test_a_negative_value_is_taken_as_the_flags_value_and_named(tmp_path, capsys, args, said):
    from splid_jax import train

    assert train.main(["--env", "point", *args, "--run-dir", str(tmp_path / "run")]) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and said in err, err
    assert not (tmp_path / "run").exists()


def test_an_error_in_a_positional_argument_names_it_as_the_usage_line_does():
    from splid_jax.cli import Parser, flag_error
    from splid_jax.common.errors import InvalidConfig

    one, several = Parser(prog="one"), Parser(prog="several")
    one.add_argument("run_dir")
    several.add_argument("run_dirs", nargs="+", metavar="RUN_DIR")
    err = InvalidConfig("run_dir", "/x", "a run directory holding config.json")
    assert flag_error(err, one) == "invalid RUN_DIR /x: must be a run directory holding config.json"
    assert flag_error(err, several) == "invalid RUN_DIR /x: must be a run directory holding config.json"
    assert flag_error(InvalidConfig("seed", 1, "even"), one) == "invalid seed=1: must be even"
