"""The one host loop: trains any ``learners.base.Algorithm``, one run or a vmapped set of sweep members.

Python runs only between compiled chunks: it logs, writes metrics.jsonl (one schema for every
algorithm, run and sweep), evaluates through the chunk, checkpoints with orbax, stops on NaN, and
resumes bit for bit. The chunk is traced, checked against the device's memory and compiled once
(``jax.jit(...).trace(...).lower().compile()``) before any state is allocated, so a run that cannot
fit is refused with its estimate and the compile is timed apart from the first chunk.

SIGINT (Ctrl-C) and SIGTERM (what a preemptible cluster sends) stop the run alike at any moment,
compilation included: the newest state that is whole is checkpointed and ``Interrupted`` raised,
which the command lines turn into exit code 130 (SIGINT) or 143 (SIGTERM)."""

from __future__ import annotations

import contextlib
import dataclasses
import io
import json
import os
import signal
import threading
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
from splid_jax.learners.base import EVAL_KEYS, Algorithm
from splid_jax.runtime import checkpoint, devices, multihost, progress

# Fields a resumed run must share with its checkpoint; the rest may change on resume.
MAY_CHANGE_ON_RESUME = frozenset({"iterations", "run_dir", "checkpoint_every", "num_devices"})
COUNTER_KEYS = ("iteration", "episodes", "env_steps", "select_steps")
METRICS = "metrics.jsonl"
SWEEP = "sweep.json"  # a sweep's config and its members' configs, from which it resumes


class RunStopped(RuntimeError):
    """The run stopped early for a reason the user must see (NaN); exit code 3."""


class Interrupted(KeyboardInterrupt):
    """SIGINT or SIGTERM stopped the run; ``exit_code`` is 128 + the signal's number."""

    def __init__(self, signum: int):
        super().__init__(signal.Signals(signum).name)
        self.signum = signum
        self.exit_code = 128 + signum


class DoesNotFit(InvalidConfig):
    """The run's arrays cannot fit the device's memory."""

    def __init__(self, message: str):
        ValueError.__init__(self, message)
        self.field, self.value, self.allowed = "num_envs", None, message


def make_env(name: str, **overrides) -> envs.GoalEnv:
    with contextlib.redirect_stdout(io.StringIO()):  # MJX prints a warp notice on import
        return envs.make(name, **overrides)


def env_settings(env: envs.GoalEnv) -> dict:
    """The task's every option as JSON stores it: a resume under other task defaults fails naming one."""
    return json.loads(json.dumps(env.settings()))


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


def identity(cfg: TrainConfig) -> dict:
    """The settings a checkpoint must share with the run resuming it, as JSON stores them."""
    return json.loads(json.dumps({k: v for k, v in cfg.to_json().items() if k not in MAY_CHANGE_ON_RESUME}))


# ---------------------------------------------------------------------------------------------
# Signals


class _Signals:
    """SIGINT and SIGTERM only set a flag, read between steps. Blocking work (tracing, compiling, a
    chunk) runs in a daemon thread while the main thread waits in short slices, so a signal is seen
    within a fraction of a second instead of after a compilation of minutes.

    Over several processes a signal is acted on only after a chunk, where every process learns of it
    (``agree``): all then stop at the same iteration and take part in its checkpoint."""

    def __init__(self):
        self.signum: int | None = None
        self.shared = jax.process_count() > 1
        self._previous: dict[int, Any] = {}

    def __enter__(self) -> _Signals:
        if threading.current_thread() is threading.main_thread():
            for sig in (signal.SIGINT, signal.SIGTERM):
                self._previous[sig] = signal.signal(sig, self._caught)
        return self

    def __exit__(self, *exc) -> None:
        for sig, handler in self._previous.items():
            signal.signal(sig, handler)

    def _caught(self, signum, frame) -> None:
        if self.signum is None:
            self.signum = signum

    def check(self) -> None:
        if self.signum is not None and not self.shared:
            raise Interrupted(self.signum)

    def agree(self) -> None:
        """``check``, after every process has told the others of the signal it got, if any."""
        if self.shared:
            self.signum = multihost.any_of(self.signum or 0) or None
            if self.signum is not None:
                raise Interrupted(self.signum)
        self.check()

    def wait(self, fn: Callable[[], Any]) -> Any:
        """``fn()`` in a daemon thread; raises ``Interrupted`` as soon as a signal came (the thread is
        left to finish or to die with the process)."""
        self.check()
        box: dict[str, Any] = {}

        def work():
            try:
                box["out"] = fn()
            except BaseException as e:  # handed to the main thread as is
                box["err"] = e

        thread = threading.Thread(target=work, name="splid_jax-work", daemon=True)
        thread.start()
        while thread.is_alive():
            thread.join(0.05)
            self.check()
        if "err" in box:
            raise box["err"]
        return box["out"]


# ---------------------------------------------------------------------------------------------
# Run directories


def read_metrics(path: str) -> list[dict]:
    return progress.read_metrics(path, checkpoint.CheckpointError)


def _write_atomic(path: str, text: str) -> None:
    tmp = path + ".tmp"
    with open(tmp, "w") as fh:
        fh.write(text)
    os.replace(tmp, path)


def write_json(path: str, obj) -> None:
    """``obj`` as JSON at ``path``, replaced whole: a reader never sees half a file."""
    _write_atomic(path, json.dumps(obj, indent=2, allow_nan=False))


def _holds_metrics(run_dir: str) -> str | None:
    """A sweep's record, or a metrics.jsonl with content in ``run_dir`` or one level below (a sweep's members)."""
    if not os.path.isdir(run_dir):
        return None
    if os.path.isfile(os.path.join(run_dir, SWEEP)):
        return os.path.join(run_dir, SWEEP)
    candidates = [os.path.join(run_dir, METRICS)]
    candidates += [os.path.join(run_dir, d, METRICS) for d in sorted(os.listdir(run_dir))]
    for path in candidates:
        if os.path.isfile(path) and os.path.getsize(path) > 0:
            return path
    return None


def check_run_dir(cfg: TrainConfig, resume: bool) -> int | None:
    """Refuses a run that would overwrite another, or a resume to fewer iterations than done;
    returns the step a resume starts from."""
    if not resume:
        if os.path.isdir(cfg.run_dir) and checkpoint.latest_step(cfg.run_dir) is not None:
            raise InvalidConfig("run_dir", cfg.run_dir, "a directory without a run in it (or pass --resume RUN_DIR)")
        held = _holds_metrics(cfg.run_dir)
        if held is not None:
            raise InvalidConfig("run_dir", cfg.run_dir, f"a directory without a run in it (it holds {held})")
        return None
    step = checkpoint.latest_step(cfg.run_dir) if os.path.isdir(cfg.run_dir) else None
    if step is None:
        raise InvalidConfig("resume", cfg.run_dir, "a run directory holding a checkpoint")
    if step > cfg.iterations:
        raise InvalidConfig("iterations", cfg.iterations, f">= {step}, the iterations {cfg.run_dir} has completed")
    return step


def check_writable(run_dir: str) -> None:
    """Creates ``run_dir`` and a file in it, then removes what it made: a read-only filesystem or
    /proc fails here, naming the directory, before any work."""
    made, path = [], os.path.abspath(run_dir)
    while not os.path.exists(path):
        made.append(path)
        path = os.path.dirname(path)
    try:
        for d in reversed(made):
            os.mkdir(d)
        probe = os.path.join(run_dir, f".write-test-{os.getpid()}")
        with open(probe, "w") as fh:
            fh.write("x")
        os.remove(probe)
    except OSError as e:
        raise InvalidConfig("run_dir", run_dir, f"a writable directory ({e.strerror})") from None
    finally:
        for d in made:
            with contextlib.suppress(OSError):
                os.rmdir(d)


# ---------------------------------------------------------------------------------------------
# Memory


def _nbytes(aval) -> int:
    shape = getattr(aval, "shape", None)
    if shape is None:
        return 0
    try:
        itemsize = np.dtype(aval.dtype).itemsize
    except TypeError:  # extended dtypes (typed PRNG keys)
        itemsize = 8
    return int(np.prod(shape, dtype=np.int64)) * itemsize


def _subjaxprs(value):
    if hasattr(value, "eqns"):
        yield value
    elif hasattr(value, "jaxpr") and hasattr(value.jaxpr, "eqns"):
        yield value.jaxpr
    elif isinstance(value, tuple | list):
        for v in value:
            yield from _subjaxprs(v)


def largest_value(jaxpr) -> int:
    """Bytes of the largest set of values one operation of ``jaxpr`` (nested ones included) makes:
    a lower bound of the memory the program needs beside its inputs and outputs."""
    best = 0
    for eqn in jaxpr.eqns:
        best = max(best, sum(_nbytes(v.aval) for v in eqn.outvars))
        for value in eqn.params.values():
            for sub in _subjaxprs(value):
                best = max(best, largest_value(sub))
    return best


def device_memory(device) -> tuple[int, str]:
    """Bytes the device may hold, and where the figure comes from."""
    stats = device.memory_stats() if hasattr(device, "memory_stats") else None
    if stats and stats.get("bytes_limit"):
        return int(stats["bytes_limit"]), f"{device.device_kind} memory"
    return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"), "host RAM"


def _gb(n: float) -> str:
    return f"{n / 1e9:.1f} GB" if n >= 1e8 else f"{n / 1e6:.1f} MB"


def _sizes(cfg: TrainConfig, members: int) -> str:
    sizes = f"num_envs={cfg.num_envs}, buffer_size={cfg.buffer_size}, eval_episodes={cfg.eval_episodes}"
    return sizes + (f", {members} sweep members" if members > 1 else "")


def check_memory(need: int, what: str, device, cfg: TrainConfig, members: int) -> None:
    limit, source = device_memory(device)
    if need > limit:
        raise DoesNotFit(
            f"invalid sizes ({_sizes(cfg, members)}): the run needs at least {_gb(need)} ({what}) "
            f"but {source} is {_gb(limit)}"
        )


# ---------------------------------------------------------------------------------------------
# The loop


def _lane_hyper(algo: Algorithm, base: TrainConfig, lane: TrainConfig) -> Any:
    """``algo.hyper()`` with each leaf named after a config field set to the member's value. A member
    may differ from the sweep's config only in its seed, its run_dir and such fields."""
    hyper = algo.hyper()
    names = [f.name for f in dataclasses.fields(hyper)] if dataclasses.is_dataclass(hyper) else list(hyper)
    for f in dataclasses.fields(TrainConfig):
        if f.name not in ("seed", "run_dir", *names) and getattr(lane, f.name) != getattr(base, f.name):
            allowed = f"{getattr(base, f.name)!r} in every member of a sweep of {algo.name} (not a traced setting)"
            raise InvalidConfig(f.name, getattr(lane, f.name), allowed)
    values = {n: jnp.asarray(getattr(lane, n), jnp.asarray(_get(hyper, n)).dtype) for n in names if hasattr(lane, n)}
    return hyper.replace(**values) if dataclasses.is_dataclass(hyper) else {**hyper, **values}


def _get(tree, name):
    return tree[name] if isinstance(tree, dict) else getattr(tree, name)


def _canonical(tree, sharding):
    """Strongly typed arrays placed as ``sharding`` says, whether they come from init or a checkpoint,
    so the compiled chunk takes a resumed state as it takes a fresh one."""
    # made on one device, then placed: XLA:CPU under jaxlib 0.10 can hang in a later program that reads
    # an array a multi-device jit wrote through out_shardings
    return jax.device_put(jax.jit(_strong)(tree), sharding)


def _strong(tree):
    return jax.tree.map(lambda x: jnp.asarray(x).astype(jnp.asarray(x).dtype), tree)


def _abstract(tree, sharding):
    return jax.tree.map(lambda x: jax.ShapeDtypeStruct(x.shape, x.dtype, sharding=sharding), tree)


def compile_hint(env: envs.GoalEnv) -> str:
    """Roughly how long the first compilation takes, as measured for this kind of task."""
    if type(env).__module__.startswith("envs.fetch"):
        return "about 3 minutes for an MJX task on a 2-core CPU, under a minute on a GPU"
    return "about 15 s on a 2-core CPU, a few seconds on a GPU"


def _record(algo, cfg, metrics: dict, i: int | None, iteration: int, total: int, chunk: int, chunk_s, wall_s):
    rec = algo.counters(iteration, total)
    rec.update({k: metrics[k] if i is None else metrics[k][i] for k in EVAL_KEYS})
    rec.update({k: v if i is None else v[i] for k, v in metrics.items() if k not in rec})
    rec = {k: v.item() if hasattr(v, "item") else v for k, v in rec.items()}
    steps = algo.counters(cfg.eval_every, chunk)
    rec["steps_per_s"] = (steps["env_steps"] + steps["select_steps"]) / max(chunk_s, 1e-9)
    rec["wall_s"] = wall_s
    return rec


def run(
    cfg: TrainConfig,
    env: envs.GoalEnv | None = None,
    *,
    algo: Algorithm | None = None,
    members: Sequence[TrainConfig] | None = None,
    resume: bool = False,
    quiet: bool = False,
) -> list[dict]:
    """Train to ``cfg.iterations``; returns the last metrics record of each lane (one for a run).

    ``members``: the configs of a sweep's members (each its own seed, run_dir and traced settings),
    trained in lock-step as one vmapped program with checkpoints under ``cfg.run_dir``. Over several
    processes every process calls it alike and each returns the records; only process 0 writes and shows."""
    env = env or make_env(cfg.env, **cfg.env_overrides())
    place = placement(cfg, None if members is None else len(members), algo)
    split_envs = place.axis == devices.ENVS and place.count > 1
    algo = algo or registry.make_algorithm(cfg, env, place.mesh if split_envs else None)
    with _Signals() as signals:
        return _Loop(cfg, env, algo, members, place, signals, quiet).run(resume)


class _Loop:
    def __init__(self, cfg, env, algo, members, place: devices.Placement, signals: _Signals, quiet: bool):
        self.cfg, self.env, self.algo, self.signals = cfg, env, algo, signals
        self.writes = multihost.is_first()  # the others compute their share and leave the run directory alone
        self.quiet = quiet or not self.writes
        self.stacked = members is not None
        self.lanes = list(members) if self.stacked else [cfg]
        self.place = place
        self.device = place.first
        self.saved_at: int | None = None
        self.groups: _Groups | None = None

    def show(self, text: str) -> None:
        progress.show(text, self.quiet)

    def meta(self) -> dict:
        meta = {"config": identity(self.cfg), "env": env_settings(self.env)}
        if self.stacked:
            meta["members"] = [identity(m) | {"run_dir": os.path.basename(m.run_dir)} for m in self.lanes]
        return meta

    def run(self, resume: bool) -> list[dict]:
        cfg = self.cfg
        step = multihost.from_first(lambda: check_run_dir(cfg, resume))
        if resume and step == cfg.iterations:
            self.show(f"{cfg.run_dir}: already complete ({step} iterations); nothing to do")
            return multihost.from_first(
                lambda: [(read_metrics(os.path.join(m.run_dir, METRICS)) or [{}])[-1] for m in self.lanes]
            )
        multihost.from_first(lambda: check_writable(cfg.run_dir))
        self.saved_at = step
        try:
            return self.start(resume, step)
        except Interrupted as stop:
            if not getattr(stop, "reported", False):
                kept = "nothing saved" if step is None else f"the checkpoint at iteration {step} is kept"
                self.show(f"interrupted ({signal.Signals(stop.signum).name}) before the first chunk ended: {kept}")
            raise

    def start(self, resume: bool, step: int | None) -> list[dict]:
        cfg, algo = self.cfg, self.algo

        keys = [jax.random.PRNGKey(m.seed) for m in self.lanes]
        hypers = [_lane_hyper(algo, cfg, m) for m in self.lanes]
        init, chunk = algo.init, algo.chunk
        place = self.place
        if self.stacked:
            keys, hyper = jnp.stack(keys), jax.tree.map(lambda *x: jnp.stack(x), *hypers)
            init, chunk = jax.vmap(init), jax.vmap(chunk)
        else:
            keys, hyper = keys[0], hypers[0]
        split = self.stacked and place.axis == devices.MEMBERS and place.count > 1
        groups = _Groups(place, len(self.lanes)) if split else None
        sharding = place.state_sharding() if groups is None else jax.sharding.SingleDeviceSharding(self.device)
        like = _abstract(jax.eval_shape(init, keys), sharding)  # the whole sweep's, as checkpoints hold it
        one = like if groups is None else groups.first(like)  # what one compiled program takes
        hyper = _canonical(hyper, sharding)
        try:
            traced = self.signals.wait(lambda: jax.jit(chunk).trace(one, groups.first(hyper) if groups else hyper))
        except OverflowError as e:  # an index past int32: sizes far beyond any device's memory
            raise DoesNotFit(
                f"invalid sizes ({_sizes(cfg, len(self.lanes))}): too large for the program's 32-bit indices, "
                "and for any device's memory"
            ) from e
        state_bytes = sum(_nbytes(x) for x in jax.tree.leaves(one))
        largest = largest_value(traced.jaxpr.jaxpr)
        check_memory(2 * state_bytes + largest, f"state {_gb(state_bytes)} twice, largest intermediate {_gb(largest)}",
                     self.device, cfg, len(self.lanes))  # fmt: skip

        processes = f" of {jax.process_count()} processes" if jax.process_count() > 1 else ""
        on = f"{place.count} devices{processes} split by {place.axis}" if place.count > 1 else self.device.platform
        self.show(f"splid_jax: algo={algo.name} env={cfg.env} device={on}"
                  + (f" members={len(self.lanes)}" if self.stacked else ""))  # fmt: skip
        self.show(f"compiling the training program ({compile_hint(self.env)}; "
                  "less when the compile cache holds it)...")  # fmt: skip
        t0 = time.perf_counter()
        compiled = self.signals.wait(lambda: traced.lower().compile())
        analysis = compiled.memory_analysis()
        if groups is not None:
            compiled = groups.compile(compiled, lambda dev: jax.jit(chunk).trace(
                groups.on(one, dev), groups.on(groups.first(hyper), dev)).lower().compile(), self.signals)  # fmt: skip
            hyper = groups.split(hyper)
        self.show(f"compiled in {time.perf_counter() - t0:.1f} s")
        if analysis is not None:
            need = analysis.argument_size_in_bytes + analysis.output_size_in_bytes + analysis.temp_size_in_bytes
            check_memory(need - analysis.alias_size_in_bytes, "as compiled", self.device, cfg, len(self.lanes))

        if resume:
            state, select_steps, wall_before = self.restore(like)
        else:
            state = _canonical(self.signals.wait(lambda: jax.jit(init)(keys)), sharding)
            state = state if groups is None else groups.split(state)
            select_steps, wall_before = [0] * len(self.lanes), 0.0
            for lane in self.lanes if self.writes else ():
                os.makedirs(lane.run_dir, exist_ok=True)
                _write_atomic(os.path.join(lane.run_dir, METRICS), "")
        for lane in self.lanes if self.writes else ():
            write_json(os.path.join(lane.run_dir, "config.json"), {**lane.to_json(), "devices": place.record()})
        if self.stacked and self.writes:
            named = [{**m.to_json(), "run_dir": os.path.basename(m.run_dir)} for m in self.lanes]
            write_json(os.path.join(cfg.run_dir, SWEEP), {"config": cfg.to_json(), "members": named})
        self.groups = groups
        return self.train(compiled, state, hyper, step or 0, select_steps, wall_before)

    def restore(self, like):
        cfg = self.cfg

        def read():
            step, state, meta = checkpoint.restore(cfg.run_dir, like, expect_meta=self.meta())
            for lane in self.lanes:  # lines written past the checkpoint are dropped, as is a torn last line
                path = os.path.join(lane.run_dir, METRICS)
                kept = [r for r in read_metrics(path) if r["iteration"] <= step]
                _write_atomic(path, "".join(json.dumps(r) + "\n" for r in kept))
            return step, state, meta

        step, state, meta = self.signals.wait(lambda: multihost.from_first(read))
        self.show(f"resumed {cfg.run_dir} at iteration {step}")
        if self.stacked and self.place.axis == devices.MEMBERS and self.place.count > 1:
            state = _Groups(self.place, len(self.lanes)).split(state)
        else:
            state = _canonical(state, self.place.state_sharding())
        return state, [int(s) for s in meta["select_steps"]], float(meta["wall_s"])

    def save(self, state, iteration: int, select_steps: list[int], wall_s: float) -> None:
        if self.saved_at == iteration:
            return
        meta = {**self.meta(), "wall_s": wall_s, "select_steps": select_steps}
        whole = state if self.groups is None else self.groups.join(state)
        if self.writes:
            checkpoint.save(self.cfg.run_dir, iteration, whole, meta)
        multihost.barrier("checkpoint saved")  # before a stop lets any process exit
        self.saved_at = iteration

    def train(self, compiled, state, hyper, iteration: int, select_steps: list[int], wall_before: float):
        cfg, algo, lanes = self.cfg, self.algo, self.lanes
        start = time.perf_counter()

        def wall() -> float:
            return wall_before + time.perf_counter() - start

        if self.stacked:
            self.show(f"sweep: {len(lanes)} members in one program, {cfg.iterations} iterations")
        last, chunks = [{}] * len(lanes), 0
        try:
            while iteration < cfg.iterations:
                t0 = time.perf_counter()
                new_state, metrics = self.signals.wait(lambda s=state: jax.block_until_ready(compiled(s, hyper)))
                chunk_s = time.perf_counter() - t0
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
                    _record(
                        algo, cfg, metrics, i if self.stacked else None, done, totals[i], int(per_lane[i]), chunk_s, now
                    )  # fmt: skip
                    for i in range(len(lanes))
                ]
                for lane, rec in zip(lanes, last, strict=True) if self.writes else ():  # past a checkpoint: dropped
                    with open(os.path.join(lane.run_dir, METRICS), "a") as fh:
                        fh.write(json.dumps(rec) + "\n")
                state, iteration, select_steps, chunks = new_state, done, totals, chunks + 1
                if self.stacked:
                    self.show(progress.sweep_line(last, cfg.iterations))
                else:
                    self.show((progress.header(last[0]) + "\n" if chunks == 1 else "") + progress.line(last[0],
                              cfg.iterations))  # fmt: skip
                if iteration == cfg.iterations or (cfg.checkpoint_every and chunks % cfg.checkpoint_every == 0):
                    self.save(state, iteration, select_steps, wall())
                self.signals.agree()
        except Interrupted as stop:
            self.save(state, iteration, select_steps, wall())
            name = signal.Signals(stop.signum).name
            self.show(f"interrupted ({name}): saved iteration {iteration} to {cfg.run_dir}; resume with --resume")
            stop.reported = True
            raise
        except RunStopped:
            self.save(state, iteration, select_steps, wall())
            raise
        return last


class _Groups:
    """A sweep's members in equal groups, one per device, each group a single-device program (the
    vmapped chunk as one device runs it). Dispatch is asynchronous, so the devices run at once; a
    group computes exactly what a sweep of its members computes on one device, and no collective
    or SPMD partitioning is involved (XLA:GPU failed to compile MJX chunks partitioned by
    ``shard_map``, and XLA:CPU under jaxlib 0.10 can hang in multi-device programs). Over several
    processes each runs the groups of its own devices, and the members' metrics and checkpointed
    state are gathered between chunks (``multihost.concat``)."""

    def __init__(self, place: devices.Placement, members: int):
        every = list(place.mesh.devices.flat)
        self.size = members // len(every)
        self.devices = {i: d for i, d in enumerate(every) if d.process_index == jax.process_index()}  # group: device

    def first(self, tree):
        return jax.tree.map(lambda x: _slice(x, 0, self.size), tree)

    def on(self, tree, device):
        sharding = jax.sharding.SingleDeviceSharding(device)
        return jax.tree.map(lambda x: jax.ShapeDtypeStruct(x.shape, x.dtype, sharding=sharding), tree)

    def split(self, tree) -> tuple:
        """This process's groups of the whole sweep's ``tree``."""
        host = jax.device_get(tree)
        return tuple(
            jax.device_put(jax.tree.map(lambda x, i=i: _slice(x, i * self.size, self.size), host), device)
            for i, device in self.devices.items()
        )

    def join(self, groups: tuple):
        """The whole sweep's state to checkpoint, on the host of every process, from this process's groups."""
        return checkpoint.on_host(multihost.concat(_concat(jax.device_get(groups))))

    def compile(self, first, compile_on, signals: _Signals):
        rest = [signals.wait(lambda d=d: compile_on(d)) for d in list(self.devices.values())[1:]]
        programs = [first, *rest]

        def run(states: tuple, hypers: tuple):
            outs = [p(s, h) for p, s, h in zip(programs, states, hypers, strict=True)]  # dispatched at once
            return tuple(o[0] for o in outs), multihost.concat(_concat([o[1] for o in outs]))

        return run


def _concat(groups):
    return jax.tree.map(lambda *xs: np.concatenate([np.asarray(x) for x in xs]), *groups)


def _slice(x, start: int, size: int):
    if isinstance(x, jax.ShapeDtypeStruct):
        return jax.ShapeDtypeStruct((size,) + x.shape[1:], x.dtype, sharding=x.sharding)
    return x[start : start + size]
