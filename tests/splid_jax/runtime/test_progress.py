"""The progress display: a closed stdout (``| head``) silences it and the run goes on to its end; on a CPU,
lines from inside a chunk (what it explored, SELECT's rounds), which change nothing the run computes."""

import dataclasses
import os
import re
import sys
import threading

import jax
import jax.numpy as jnp
import pytest

import envs
from splid_jax import train
from splid_jax.common import ticks
from splid_jax.common.ticks import EXPLORED, ITERATION, ROUND
from splid_jax.config import TrainConfig
from splid_jax.runtime import checkpoint, loop, programs, progress
from splid_jax.runtime.progress import Watch

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


class Clock:
    def __init__(self):
        self.now = 0.0

    def __call__(self):
        return self.now


def counters(iteration, select_steps):
    return {"iteration": iteration, "episodes": 4 * iteration}


def test_a_watch_shows_what_the_chunk_did_at_most_every_interval():
    clock, shown = Clock(), []
    watch = Watch(shown.append, 2, counters, interval=10.0, clock=clock)
    with watch.chunk(6):  # after 6 iterations
        watch.seen(EXPLORED, 6)
        clock.now = 9.0
        watch.seen(ROUND, 50)
        assert shown == []  # not yet due
        clock.now = 10.0
        watch.seen(ROUND, 20)
        clock.now = 15.0
        watch.seen(ROUND, 0)
        watch.seen(ITERATION, 7)
        clock.now = 21.0
        watch.seen(EXPLORED, 7)
        clock.now = 31.0
        watch.seen(ITERATION, 8)
    watch.seen(EXPLORED, 8)  # a chunk no longer waited for (a signal stopped the run) shows nothing
    assert shown == [
        "  ... iteration 1/2 of the chunk: explored, SELECT round 2 (20 verdicts left); 28 episodes explored, "
        "10 s into the chunk",
        "  ... iteration 2/2 of the chunk: explored; 32 episodes explored, 21 s into the chunk",
        "  ... 2 iterations trained, evaluating; 32 episodes explored, 31 s into the chunk",
    ]


def test_a_watch_shows_a_line_where_no_tick_comes():
    clock, shown, line = Clock(), [], threading.Event()
    watch = Watch(lambda text: (shown.append(text), line.set()), 3, counters, interval=0.01, clock=clock)
    with watch.chunk(0):
        watch.seen(ITERATION, 1)
        assert shown == []
        clock.now = 12.0  # a long exploration: the timer's line says so
        assert line.wait(30)
    assert shown == ["  ... iteration 2/3 of the chunk: started; 4 episodes explored, 12 s into the chunk"]


def test_only_a_watched_trace_carries_the_ticks():
    def train(x, hyper):
        ticks.tick(ticks.ITERATION, lambda: x.astype(jnp.int32))
        return x + hyper, ()

    like = jax.ShapeDtypeStruct((), jnp.float32)
    watch = Watch(lambda text: None, 1, counters)
    quiet, watched = (programs.trace([train], like, like, w)[0].jaxpr for w in (None, watch))
    assert "callback" not in str(quiet) and "callback" in str(watched)


@dataclasses.dataclass
class Ticking:
    """An ``learners.base.Algorithm`` that compiles in a moment and ticks at each iteration, as learners do."""

    env: object
    cfg: TrainConfig
    name = "ticking"

    def init(self, key):
        return {"w": jnp.zeros(()), "key": key, "iteration": jnp.int32(0)}

    def hyper(self, cfg=None):
        return {}

    def chunk(self, state, hyper):
        def one(s, _):
            s = {**s, "w": s["w"] + 1.0, "iteration": s["iteration"] + 1}
            ticks.tick(ITERATION, lambda: s["iteration"], after=s["w"])
            return s, None

        s, _ = jax.lax.scan(one, state, None, length=self.cfg.eval_every)
        metrics = {key: s["w"] for key in ("eval_success", "eval_success_final", "eval_return")}
        return s, {**metrics, "finite": jnp.isfinite(s["w"])}

    def counters(self, iteration, select_steps):
        return {"iteration": iteration, "episodes": iteration * 4, "env_steps": iteration * 200, "select_steps": 0}


def test_only_a_single_run_with_its_display_on_shows_lines_inside_its_chunks(tmp_path, capsys):
    cfg = TrainConfig(env="point", num_envs=4, eval_every=2, iterations=4, eval_episodes=4, run_dir=str(tmp_path / "a"))
    env = envs.make("point")
    loop.run(cfg, env, algo=Ticking(env, cfg), inside_every=0)
    inside = [text for text in capsys.readouterr().out.splitlines() if text.startswith("  ... ")]
    assert [text[: text.index(";")] for text in inside] == 2 * [
        "  ... iteration 2/2 of the chunk: started", "  ... 2 iterations trained, evaluating"
    ], inside  # fmt: skip
    lanes = [dataclasses.replace(cfg, seed=s, run_dir=os.path.join(cfg.run_dir, f"s{s}")) for s in (0, 1)]
    sweep = dataclasses.replace(cfg, run_dir=str(tmp_path / "sweep"))
    loop.run(sweep, env, algo=Ticking(env, sweep), members=lanes, inside_every=0)  # a sweep: one line per chunk
    assert "  ... " not in capsys.readouterr().out  # (a quiet run shows nothing: the next test)


# SMALL's settings, 5 iterations: one chunk, whose evaluation program the three runs of this file share
ONE_CHUNK = dict(env="point", num_envs=4, eval_episodes=8, eval_every=5, bc_steps=5, batch_size=16, hidden=(16,),
                 iterations=5)  # fmt: skip
ROUNDS = re.compile(r"iteration (\d)/5 of the chunk: explored, SELECT round (\d+) \(([\d,]+) verdicts left\)")


@pytest.mark.slow
def test_a_splid_chunk_on_a_cpu_shows_its_exploration_and_select_inside_it_and_computes_the_same(tmp_path, capsys):
    quiet = loop.run(TrainConfig(**ONE_CHUNK, run_dir=str(tmp_path / "quiet")), quiet=True)
    assert capsys.readouterr().out == ""
    shown = loop.run(TrainConfig(**ONE_CHUNK, run_dir=str(tmp_path / "shown")), inside_every=0)
    out = capsys.readouterr().out
    assert progress.NOT_CACHED in out
    inside = [text for text in out.splitlines() if text.startswith("  ... ")]
    assert out.index(inside[-1]) < out.index("   5/5 ")  # all before the chunk's own line
    assert inside[0].startswith("  ... iteration 1/5 of the chunk: explored; 4 episodes explored, ")
    rounds = [ROUNDS.search(text).groups() for text in inside if ROUNDS.search(text)]
    for n in "12345":  # every round of each iteration's SELECT, until no verdict is left
        done = [(int(r), int(left.replace(",", ""))) for i, r, left in rounds if i == n]
        assert [r for r, _ in done] == list(range(1, len(done) + 1)) and len(done) > 1
        assert [left for _, left in done] == sorted((left for _, left in done), reverse=True) and done[-1][1] == 0
        explored = f"  ... iteration {n}/5 of the chunk: explored; {4 * int(n)} episodes explored, "
        assert sum(text.startswith(explored) for text in inside) == 1
    assert inside[-1].startswith("  ... 5 iterations trained, evaluating; 20 episodes explored")
    timing = ("wall_s", "chunk_s", "steps_per_s")
    assert [{k: v for k, v in r.items() if k not in timing} for r in shown] == [
        {k: v for k, v in r.items() if k not in timing} for r in quiet
    ]
