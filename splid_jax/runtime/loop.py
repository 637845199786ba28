"""The one host loop: trains any ``learners.base.Algorithm``, one run or a vmapped set of sweep members.

Python runs between compiled chunks (on a CPU with the display on, also at the ticks inside one, to show them:
``progress.Watch``): it logs, writes metrics.jsonl (one schema for every algorithm, run and sweep), evaluates through
the chunk, checkpoints with orbax, stops on NaN, and resumes bit for bit. The state's size is checked against the
device's memory before anything is built, and the chunk's intermediates once it is traced; the chunk is compiled once,
a learner's training and report as two programs side by side (``programs``), timed apart from the first chunk.
While XLA compiles, the keys, the settings and the initial state are built on the device in a thread
(built beside the trace, they slowed it), and on one process each checkpoint is written while the next chunk
runs, so neither waits on the other (experiments/NOTES.md, "The host loop's overlaps").

A signal stops the run at any moment with its newest whole state checkpointed (``signals``); the run
directory's files are ``run_files``', the memory check ``memory``'s, a sweep split over devices
``groups``'."""

from __future__ import annotations

import contextlib
import json
import os
import signal
import sys
import time
from collections.abc import Callable, Sequence
from typing import Any

import jax
import jax.numpy as jnp
import numpy as np

import envs
from splid_jax.common.errors import InvalidConfig
from splid_jax.config import TrainConfig
from splid_jax.learners import registry
from splid_jax.learners.base import Algorithm
from splid_jax.runtime import checkpoint, devices, lock, multihost, programs, progress
from splid_jax.runtime.groups import Groups
from splid_jax.runtime.memory import DoesNotFit, check_memory, compile_hint, gigabytes, nbytes, sizes
from splid_jax.runtime.run_files import (
    METRICS,
    SWEEP,
    check_run_dir,
    check_writable,
    env_settings,
    identity,
    metrics_record,
    read_metrics,
    warn_of_gap,
    write_atomic,
    write_json,
)
from splid_jax.runtime.signals import Interrupted, SaveAbandoned, Signals
from splid_jax.runtime.stalls import late_after, late_message
from splid_jax.runtime.states import abstract, canonical, initial_state

COUNTER_KEYS = ("iteration", "episodes", "env_steps", "select_steps")


class RunStopped(RuntimeError):
    """The run stopped early for a reason the user must see (NaN); exit code 3."""


def placement(cfg: TrainConfig, members: int | None, algo: Algorithm | None = None) -> devices.Placement:
    """The devices a run (``members`` None) or a sweep of ``members`` uses (``cfg.num_devices``)."""
    if members is not None:
        return devices.place(cfg.num_devices, members, devices.MEMBERS)
    if algo is not None:  # built by the caller: its own mesh, if any
        mesh = getattr(algo, "mesh", None)
        return devices.Placement(mesh, devices.ENVS) if mesh is not None else devices.place(1, 1, devices.ENVS)
    if not registry.get(cfg.algo).splits_envs:
        allowed = f"1 or 0 for a single {cfg.algo} run (a sweep of {cfg.algo} splits its members)"
        if cfg.num_devices > 1:
            raise InvalidConfig("num_devices", cfg.num_devices, allowed)
        return devices.place(1, 1, devices.ENVS)
    return devices.place(cfg.num_devices, cfg.num_envs, devices.ENVS)


def _lane_hyper(algo: Algorithm, base: TrainConfig, lane: TrainConfig) -> Any:
    """``algo.hyper(lane)``: a member may differ from the sweep's config only in its seed, its run_dir
    and the learner's traced settings (its registry entry's ``sweeps``)."""
    traced = registry.get(base.algo).sweeps
    for f in TrainConfig.settings_fields():
        if f.name not in ("seed", "run_dir", *traced) and getattr(lane, f.name) != getattr(base, f.name):
            allowed = f"{getattr(base, f.name)!r} in every member of a sweep of {algo.name} (not a traced setting)"
            raise InvalidConfig(f.name, getattr(lane, f.name), allowed)
    return algo.hyper(lane)


def run(
    cfg: TrainConfig,
    env: envs.GoalEnv | None = None,
    *,
    algo: Algorithm | None = None,
    members: Sequence[TrainConfig] | None = None,
    resume: bool = False,
    quiet: bool = False,
    on_record: Callable[[str, dict], None] | None = None,
    inside_every: float = 10.0,
) -> list[dict]:
    """Train to ``cfg.iterations``; returns the last metrics record of each lane (one for a run).

    ``on_record(run_dir, record)`` sees every record as it is written to its lane's metrics.jsonl (a TensorBoard
    writer, say). On one CPU with the display on, what a chunk did is shown every ``inside_every`` s (``Watch``).

    ``members``: the configs of a sweep's members (each its own seed, run_dir and traced settings),
    trained in lock-step as one vmapped program with checkpoints under ``cfg.run_dir``. Over several
    processes every process calls it alike and each returns the records; only process 0 writes and shows."""
    with Signals() as signals, lock.hold(cfg.run_dir, multihost.is_first(), "resume" if resume else "run_dir"):
        env = env or signals.wait(cfg.make_env)
        place = placement(cfg, None if members is None else len(members), algo)
        split_envs = place.axis == devices.ENVS and place.count > 1
        algo = algo or signals.wait(lambda: registry.make_algorithm(cfg, env, place.mesh if split_envs else None))
        return _Loop(cfg, env, algo, members, place, signals, quiet, on_record, inside_every).run(resume)


class _Loop:
    def __init__(self, cfg, env, algo, members, place: devices.Placement, signals: Signals, quiet: bool,
                 on_record: Callable[[str, dict], None] | None = None, inside_every: float = 10.0):  # fmt: skip
        self.cfg, self.env, self.algo, self.signals, self.on_record = cfg, env, algo, signals, on_record
        self.writes = multihost.is_first()  # the others compute their share and leave the run directory alone
        self.quiet = quiet or not self.writes
        self.stacked, self.lanes = members is not None, [cfg] if members is None else list(members)
        self.place, self.device = place, place.first
        self.saved_at: int | None = None
        self.groups: Groups | None = None
        self.writing: Callable[[], None] | None = None  # a checkpoint write running beside the next chunk
        alone = not self.quiet and not self.stacked and place.count == 1 and self.device.platform == "cpu"
        self.watch = progress.Watch(self.show, cfg.eval_every, algo.counters, inside_every) if alone else None

    def show(self, text: str) -> None:
        progress.show(text, self.quiet)

    def meta(self) -> dict:
        meta = {"config": identity(self.cfg), "env": env_settings(self.env)}
        if self.stacked:
            meta["members"] = [identity(m) | {"run_dir": os.path.basename(m.run_dir)} for m in self.lanes]
        return meta

    def run(self, resume: bool) -> list[dict]:
        cfg = self.cfg
        step = multihost.from_first(lambda: check_run_dir(cfg, resume, self.meta()))
        if resume and step == cfg.iterations:
            self.show(f"{cfg.run_dir}: already complete ({step} iterations); nothing to do")
            return multihost.from_first(
                lambda: [(read_metrics(os.path.join(m.run_dir, METRICS)) or [{}])[-1] for m in self.lanes]
            )
        if resume and step is None:
            self.show(f"{cfg.run_dir}: stopped before its first checkpoint; starting it again, its records dropped")
            resume = False
        multihost.from_first(lambda: check_writable(cfg.run_dir))
        self.saved_at = step
        try:
            return self.start(resume, step)
        except Interrupted as stop:
            if not getattr(stop, "reported", False):
                kept = "nothing saved" if step is None else f"the checkpoint at iteration {step} is kept"
                self.show(f"interrupted ({signal.Signals(stop.signum).name}) before the first chunk ended: {kept}")
            raise
        except Exception as e:  # a full disk or a refused write, whichever met it: one line, the last checkpoint kept
            failure = checkpoint.write_failure(e)
            if failure is None:
                raise
            kept = "nothing saved" if self.saved_at is None else f"the checkpoint at iteration {self.saved_at} is kept"
            if checkpoint.is_no_space(e):
                raise checkpoint.NoSpace(f"no space left on the device writing {cfg.run_dir}: {kept}") from None
            raise checkpoint.WriteFailed(f"cannot write {cfg.run_dir} ({failure[1]}): {kept}") from None

    def start(self, resume: bool, step: int | None) -> list[dict]:
        cfg, algo = self.cfg, self.algo

        place = self.place
        split = self.stacked and place.axis == devices.MEMBERS and place.count > 1
        self.check_state_fits(split)

        def stack():  # seconds for a sweep of thousands of members: a signal must not wait for it
            keys = [jax.random.PRNGKey(m.seed) for m in self.lanes]
            hypers = [_lane_hyper(algo, cfg, m) for m in self.lanes]
            if self.stacked:
                return jnp.stack(keys), jax.tree.map(lambda *x: jnp.stack(x), *hypers)
            return keys[0], hypers[0]

        keys_like, hyper_like = self.signals.wait(lambda: jax.eval_shape(stack))  # no device work yet
        init = jax.vmap(algo.init) if self.stacked else algo.init
        fns = programs.parts(algo, self.stacked)
        groups = Groups(place, len(self.lanes)) if split else None
        sharding = place.state_sharding() if groups is None else jax.sharding.SingleDeviceSharding(self.device)
        like = abstract(jax.eval_shape(init, keys_like), sharding)  # the whole sweep's, as checkpoints hold it
        one = like if groups is None else groups.first(like)  # what one compiled program takes
        hyper_one = abstract(hyper_like, sharding)  # strongly typed, as canonical makes the values

        def made():  # the device's first programs, built while the chunk is compiled
            keys, hyper = stack()
            if resume:
                return canonical(hyper, sharding), None
            state = initial_state(algo.init, keys, self.stacked, self.device.platform == "cpu")
            return canonical(hyper, sharding), canonical(state, sharding)

        t0 = time.perf_counter()
        try:
            traced = self.signals.wait(
                lambda: programs.trace(fns, one, groups.first(hyper_one) if groups else hyper_one, self.watch)
            )
        except OverflowError as e:  # an index past int32: sizes far beyond any device's memory
            raise DoesNotFit(
                f"invalid sizes ({sizes(cfg, len(self.lanes))}): too large for the program's 32-bit indices, "
                "and for any device's memory"
            ) from e
        traced_s = time.perf_counter() - t0
        state_bytes = sum(nbytes(x) for x in jax.tree.leaves(one))
        largest = programs.largest(traced)
        what = f"state {gigabytes(state_bytes)} twice, largest intermediate {gigabytes(largest)}"
        check_memory(2 * state_bytes + largest, what, self.device, cfg, len(self.lanes))

        processes = f" of {jax.process_count()} processes" if jax.process_count() > 1 else ""
        on = f"{place.count} devices{processes} split by {place.axis}" if place.count > 1 else self.device.platform
        self.show(f"splid_jax: algo={algo.name} env={cfg.env} device={on}"
                  + (f" members={len(self.lanes)}" if self.stacked else ""))  # fmt: skip
        cached = "less when the compile cache holds it" if self.watch is None else progress.NOT_CACHED
        self.show(f"compiling the training program ({compile_hint(self.env)}; {cached})...")
        building = self.signals.begin(made)  # beside the compile: beside the trace it slowed the trace
        t0 = time.perf_counter()
        pending = []
        if groups is not None:  # the other devices' programs, compiled beside the first device's
            on_device = lambda dev: programs.trace(fns, groups.on(one, dev), groups.on(groups.first(hyper_one), dev))  # noqa: E731
            pending = groups.begin(lambda dev: programs.compile_all(on_device(dev), self.signals), self.signals)
        try:
            compiled = programs.compile_all(traced, self.signals)
        except Exception as e:  # re-raised unless it is a physics kernel's
            hint = self.env.kernel_fallback(e)
            if hint is None:
                raise
            raise InvalidConfig("env_options", cfg.env_options, hint) from e
        need = compiled.bytes_needed()
        if groups is not None:
            compiled = groups.compile(compiled, pending, self.signals)
        self.show(f"compiled in {time.perf_counter() - t0:.1f} s (traced before it in {traced_s:.1f} s)")
        if need is not None:
            check_memory(need, "as compiled", self.device, cfg, len(self.lanes))
        hyper, initial = self.signals.wait(building)
        hyper = hyper if groups is None else groups.split(hyper)

        if resume:
            state, select_steps, wall_before = self.restore(like)
        else:
            state = initial if groups is None else groups.split(initial)
            select_steps, wall_before = [0] * len(self.lanes), 0.0
            for lane in self.lanes if self.writes else ():
                os.makedirs(lane.run_dir, exist_ok=True)
                write_atomic(os.path.join(lane.run_dir, METRICS), "")
        for i, lane in enumerate(self.lanes) if self.writes else ():
            placed = place.record(i if self.stacked else None, len(self.lanes))
            record = {**lane.to_json(), "devices": placed, "physics": self.env.physics_in_use()}
            write_json(os.path.join(lane.run_dir, "config.json"), record)
        if self.stacked and self.writes:
            named = [{**m.to_json(), "run_dir": os.path.basename(m.run_dir)} for m in self.lanes]
            write_json(os.path.join(cfg.run_dir, SWEEP), {"config": cfg.to_json(), "members": named})
        self.groups = groups
        return self.train(compiled, state, hyper, step or 0, select_steps, wall_before)

    def warn_late(self, iteration: int, ran_s: float, slowest_s: float) -> None:
        if self.writes:
            print(f"warning: {late_message(self.cfg, iteration, ran_s, slowest_s)}", file=sys.stderr, flush=True)

    def check_state_fits(self, split: bool) -> None:
        """One member's state times the members a device holds, twice (the state and its update),
        against the device's memory: a grid of thousands is refused before anything is stacked or traced."""
        key = jax.eval_shape(jax.random.PRNGKey, 0)  # abstract: the device's first program is built beside the trace
        one = sum(nbytes(x) for x in jax.tree.leaves(jax.eval_shape(self.algo.init, key)))
        held = -(-len(self.lanes) // self.place.count) if split else len(self.lanes)
        what = f"state {gigabytes(one)} per member x {held} members, twice" if self.stacked else "state twice"
        check_memory(2 * one * held, what, self.device, self.cfg, len(self.lanes))

    def restore(self, like):
        cfg = self.cfg

        def read():
            step, state, meta = checkpoint.restore(cfg.run_dir, like, expect_meta=self.meta())
            for lane in self.lanes:  # lines written past the checkpoint are dropped, as is a torn last line
                path = os.path.join(lane.run_dir, METRICS)
                kept = [r for r in read_metrics(path) if r["iteration"] <= step]
                warn_of_gap(path, kept, step)
                write_atomic(path, "".join(json.dumps(r) + "\n" for r in kept))
            return step, state, meta

        step, state, meta = self.signals.wait(lambda: multihost.from_first(read))
        self.show(f"resumed {cfg.run_dir} at iteration {step}")
        if self.stacked and self.place.axis == devices.MEMBERS and self.place.count > 1:
            state = Groups(self.place, len(self.lanes)).split(state)
        else:
            state = canonical(state, self.place.state_sharding())
        return state, [int(s) for s in meta["select_steps"]], float(meta["wall_s"])

    def wait_for_write(self) -> None:
        """The checkpoint write left running beside a chunk, finished (or its error raised). A plain join,
        which a signal does not cut short: the write's own grace (``Signals.finish``) bounds it."""
        writing, self.writing = self.writing, None
        if writing is not None:
            writing()

    def save(self, state, iteration: int, select_steps: list[int], wall_s: float) -> None:
        if self.saved_at == iteration:
            return
        meta = {**self.meta(), "wall_s": wall_s, "select_steps": select_steps}

        def write():  # the join too: it reads the devices' arrays, which a stuck program may never free
            whole = state if self.groups is None else self.groups.join(state)
            if self.writes:
                checkpoint.save(self.cfg.run_dir, iteration, whole, meta)

        try:
            self.signals.finish(write)
        except SaveAbandoned as stop:
            kept = "nothing saved" if self.saved_at is None else f"iteration {self.saved_at} is kept"
            self.show(f"interrupted ({signal.Signals(stop.signum).name}) while saving iteration {iteration}, "
                      f"not waited for: the last whole checkpoint, {kept}, in {self.cfg.run_dir}")  # fmt: skip
            stop.reported = True
            raise
        multihost.barrier("checkpoint saved")  # before a stop lets any process exit
        self.saved_at = iteration

    def train(self, compiled, state, hyper, iteration: int, select_steps: list[int], wall_before: float):
        cfg, algo, lanes = self.cfg, self.algo, self.lanes
        start = time.perf_counter()

        def wall() -> float:
            return wall_before + time.perf_counter() - start

        if self.stacked:
            self.show(f"sweep: {len(lanes)} members in one program, {cfg.iterations} iterations")
        last, chunks, slowest = [{}] * len(lanes), 0, 0.0
        try:
            while iteration < cfg.iterations:
                t0 = time.perf_counter()
                with self.watch.chunk(iteration) if self.watch else contextlib.nullcontext():
                    new_state, metrics = self.signals.wait(
                        lambda s=state: jax.block_until_ready(compiled(s, hyper)),
                        late_after(slowest),
                        lambda ran, i=iteration, was=slowest: self.warn_late(i, ran, was),
                    )
                chunk_s = time.perf_counter() - t0
                slowest = max(slowest, chunk_s)
                metrics = jax.device_get(metrics)
                finite = np.asarray(metrics.pop("finite")).reshape(-1)
                done = iteration + cfg.eval_every
                if not finite.all():
                    bad = ", ".join(os.path.basename(lanes[i].run_dir) for i in np.flatnonzero(~finite))
                    raise RunStopped(
                        f"non-finite loss or parameters after iteration {done}"
                        + (f" in {bad}" if self.stacked else "")
                        + f"; stopped, the last good state (iteration {iteration}) is kept in {cfg.run_dir}"
                    )
                none = np.zeros((len(lanes), cfg.eval_every))  # learners that replay nothing report no steps
                per_lane = np.asarray(metrics.pop("select_steps", none), np.int64)
                per_lane = per_lane.reshape(len(lanes), -1).sum(axis=-1)
                totals = [t + int(c) for t, c in zip(select_steps, per_lane, strict=True)]
                now = wall()
                last = [
                    metrics_record(
                        algo, cfg, metrics, i if self.stacked else None, done, totals[i], int(per_lane[i]), chunk_s, now
                    )  # fmt: skip
                    for i in range(len(lanes))
                ]
                for lane, rec in zip(lanes, last, strict=True) if self.writes else ():  # past a checkpoint: dropped
                    with open(os.path.join(lane.run_dir, METRICS), "a") as fh:
                        fh.write(json.dumps(rec) + "\n")
                    if self.on_record is not None:
                        self.on_record(lane.run_dir, rec)
                state, iteration, select_steps, chunks = new_state, done, totals, chunks + 1
                if self.stacked:
                    self.show(progress.sweep_line(last, cfg.iterations))
                else:
                    self.show((progress.header(last[0]) + "\n" if chunks == 1 else "") + progress.line(last[0],
                              cfg.iterations))  # fmt: skip
                if iteration == cfg.iterations or (cfg.checkpoint_every and chunks % cfg.checkpoint_every == 0):
                    self.wait_for_write()
                    if iteration < cfg.iterations and not self.signals.shared:  # written beside the next chunk
                        args = (state, iteration, select_steps, wall())
                        self.writing = self.signals.begin(lambda a=args: self.save(*a))
                    else:
                        self.save(state, iteration, select_steps, wall())
                self.signals.agree()
        except SaveAbandoned:
            raise
        except Interrupted as stop:
            self.wait_for_write()
            self.save(state, iteration, select_steps, wall())
            name = signal.Signals(stop.signum).name
            self.show(f"interrupted ({name}): saved iteration {iteration} to {cfg.run_dir}; resume with --resume")
            stop.reported = True
            raise
        except RunStopped:
            self.wait_for_write()
            self.save(state, iteration, select_steps, wall())
            raise
        except Exception:  # the chunk's own error is the one to report; a write under way still ends whole
            with contextlib.suppress(Exception):
                self.wait_for_write()
            raise
        return last
