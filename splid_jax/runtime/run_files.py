"""A run directory's files: config.json, metrics.jsonl (one line per chunk), a sweep's sweep.json, and
the checks that keep one run from overwriting another."""

from __future__ import annotations

import dataclasses
import json
import os
import sys

import envs
from envs.base import recorded_default
from splid_jax.common.errors import InvalidConfig
from splid_jax.common.paths import unwritable
from splid_jax.common.values import format_overrides, parse_overrides
from splid_jax.config import TrainConfig
from splid_jax.learners.base import EVAL_KEYS
from splid_jax.runtime import checkpoint, progress

# Fields a resumed run must share with its checkpoint; the rest may change on resume. The task's options may be
# spelt anew: its checkpoint's task settings are what must match (``recorded_task``).
MAY_CHANGE_ON_RESUME = frozenset({"iterations", "run_dir", "checkpoint_every", "num_devices", "env_options"})
METRICS = "metrics.jsonl"
SWEEP = "sweep.json"  # a sweep's config and its members' configs, from which it resumes
EXPORT = "export.json"  # an exported policy's source run and checkpoint (``splid_jax.export``); not resumed


def env_settings(env: envs.GoalEnv) -> dict:
    """The task's every option as JSON stores it: a resume under other task defaults fails naming one."""
    return json.loads(json.dumps(env.settings()))


def note_task_changes(run_dir: str, saved: dict, env: envs.GoalEnv) -> None:
    """Name, on stderr, the task's options that differ from those a checkpoint recorded (``saved``): a
    policy is still worth a look under a changed task, so loaders say it rather than stop."""
    now = env_settings(env)
    fields = {f.name: f for f in dataclasses.fields(env)}

    def value(settings: dict, k: str):  # an option left out of the settings is at its recorded default
        if k in settings or k not in fields:
            return settings.get(k)
        return json.loads(json.dumps(recorded_default(fields[k])))

    changed = [k for k in {**saved, **now} if value(saved, k) != value(now, k)]
    if changed:
        what = ", ".join(f"{k}={value(saved, k)!r} then, {value(now, k)!r} now" for k in changed)
        print(f"note: {run_dir} was trained on another version of the task ({what})", file=sys.stderr)


def identity(cfg: TrainConfig) -> dict:
    """The settings a checkpoint must share with the run resuming it, as JSON stores them. A setting
    added after runs were recorded (field metadata ``recorded_when_set``) is left out at its default and at
    its ``unrecorded`` value (how those runs behaved), so they still resume."""
    fields = cfg.settings_fields()
    later = {
        f.name: (recorded_default(f), f.default)
        for f in fields
        if f.metadata.get("recorded_when_set")
    }
    kept = {
        k: v for k, v in cfg.to_json().items() if k not in MAY_CHANGE_ON_RESUME and not (k in later and v in later[k])
    }
    return json.loads(json.dumps(kept))


def read_metrics(path: str) -> list[dict]:
    return progress.read_metrics(path, checkpoint.CheckpointError)


def write_atomic(path: str, text: str) -> None:
    tmp = path + ".tmp"
    with open(tmp, "w") as fh:
        fh.write(text)
    os.replace(tmp, path)


def write_json(path: str, obj) -> None:
    """``obj`` as JSON at ``path``, replaced whole: a reader never sees half a file."""
    write_atomic(path, json.dumps(obj, indent=2, allow_nan=False))


def holds_metrics(run_dir: str) -> str | None:
    """A sweep's record, or a metrics.jsonl with content in ``run_dir`` or one level below (a sweep's members)."""
    if not os.path.isdir(run_dir):
        return None
    if os.path.isfile(os.path.join(run_dir, SWEEP)):
        return os.path.join(run_dir, SWEEP)
    return recorded(run_dir)


def recorded(run_dir: str) -> str | None:
    """A metrics.jsonl with content in ``run_dir`` or one level below (a sweep's members)."""
    if not os.path.isdir(run_dir):
        return None
    candidates = [os.path.join(run_dir, METRICS)]
    candidates += [os.path.join(run_dir, d, METRICS) for d in sorted(os.listdir(run_dir))]
    for path in candidates:
        if os.path.isfile(path) and os.path.getsize(path) > 0:
            return path
    return None


def holds_run(run_dir: str) -> bool:
    """Whether ``run_dir`` holds a run that ``--resume`` continues: a checkpoint, or the config.json or
    sweep.json written before its first chunk (then it starts again)."""
    if not os.path.isdir(run_dir):
        return False
    if any(os.path.isfile(os.path.join(run_dir, f)) for f in ("config.json", SWEEP)):
        return True
    return checkpoint.latest_step(run_dir) is not None


def enclosing_run(path: str) -> str | None:
    """The nearest directory above ``path`` that holds a run or a sweep (its config.json beside its
    metrics or checkpoints, or a sweep.json), or None: a run made in another's directory goes with it
    when that one rotates a checkpoint out or is deleted."""
    here = os.path.dirname(os.path.abspath(path))
    while True:
        marks = [os.path.exists(os.path.join(here, f)) for f in ("config.json", METRICS, "checkpoints", SWEEP)]
        if (marks[0] and (marks[1] or marks[2])) or marks[3]:
            return here
        parent = os.path.dirname(here)
        if parent == here:
            return None
        here = parent


def check_run_dir(cfg: TrainConfig, resume: bool, meta: dict | None = None) -> int | None:
    """Refuses a run that would overwrite another, or a resume to fewer iterations than done or with
    settings other than its checkpoint's ``meta``; returns the step a resume starts from, None where the
    run stopped before its first whole checkpoint (it then starts again, its records dropped)."""
    if not resume:
        outer = enclosing_run(cfg.run_dir)
        if outer is not None:
            raise InvalidConfig("run_dir", cfg.run_dir, f"a directory outside any other run (it lies in {outer})")
        hint = f"; to continue that run: --resume {cfg.run_dir}"
        if os.path.isdir(cfg.run_dir) and checkpoint.latest_step(cfg.run_dir) is not None:
            why = f"a directory without a run in it (it holds a checkpoint{hint})"
            raise InvalidConfig("run_dir", cfg.run_dir, why)
        held = holds_metrics(cfg.run_dir)
        if held is not None:
            hint = hint if holds_run(cfg.run_dir) else ""
            raise InvalidConfig("run_dir", cfg.run_dir, f"a directory without a run in it (it holds {held}{hint})")
        return None
    if not holds_run(cfg.run_dir):
        raise InvalidConfig("resume", cfg.run_dir, "a run directory holding a checkpoint or its config.json")
    step = checkpoint.latest_step(cfg.run_dir)
    if step is None:
        check_restartable(cfg)
    if step is not None and step > cfg.iterations:
        raise InvalidConfig("iterations", cfg.iterations, f">= {step}, the iterations {cfg.run_dir} has completed")
    if step is not None and meta is not None:
        saved = checkpoint.saved_meta(cfg.run_dir, step)  # read once for both checks
        recorded_task(cfg, saved, meta.get("env"))
        checkpoint.check_meta(cfg.run_dir, step, meta, saved)
    return step


def recorded_task(cfg: TrainConfig, saved: dict | None, now: dict | None) -> None:
    """Refuses a resume whose task differs from the one its checkpoint recorded (the task's defaults changed
    since, say), naming the ``--env-options`` that rebuild the recorded one."""
    was = (saved or {}).get("env")
    if not isinstance(was, dict) or not isinstance(now, dict) or was.get("task") != now.get("task"):
        return
    fields = {f.name: f for f in dataclasses.fields(envs.task_class(cfg.env))}
    unset = object()
    changed = [k for k in now if k in fields and was.get(k, unset) != now[k]]
    if not changed:
        return
    spelt = parse_overrides(cfg.env_options)
    for k in changed:
        spelt[k] = was[k] if k in was else recorded_default(fields[k])
    why = f"the task {cfg.run_dir} was trained on, whose options differ ({', '.join(changed)})"
    raise InvalidConfig("env_options", cfg.env_options, f"{why}: --env-options {format_overrides(spelt)}")


def check_restartable(cfg: TrainConfig) -> None:
    """A run without a checkpoint starts again, its records dropped: refused where they are more than the
    chunks a run writes before its first checkpoint is whole (its checkpoints were deleted, say)."""
    path = recorded(cfg.run_dir)
    if path is None or not cfg.checkpoint_every:
        return
    with open(path, "rb") as fh:
        records = sum(1 for line in fh if line.strip())
    if records > cfg.checkpoint_every + 1:  # one checkpoint may still be under way beside the next chunk
        why = (f"a run with a checkpoint to continue from ({path} holds {records} records but there is no "
               "checkpoint; move it away to start the run again)")  # fmt: skip
        raise InvalidConfig("resume", cfg.run_dir, why)


def check_writable(run_dir: str) -> None:
    """A read-only filesystem or /proc fails here, naming the directory, before any work."""
    why = unwritable(run_dir)
    if why:
        raise InvalidConfig("run_dir", run_dir, f"a writable directory ({why})")


def warn_of_gap(path: str, kept: list[dict], step: int) -> None:
    """A metrics file that stops short of its checkpoint (a torn last line, a deleted file) would
    resume with a gap in its curve: said on stderr, since the records cannot be made again."""
    last = kept[-1]["iteration"] if kept else 0
    if last < step:
        what = "is missing or empty" if not kept else f"ends at iteration {last}"
        print(f"warning: {path} {what} but the checkpoint is at iteration {step}: the records of iterations "
              f"{last + 1}-{step} are lost, so its curve has a gap there", file=sys.stderr)  # fmt: skip


def metrics_record(algo, cfg, metrics: dict, i: int | None, iteration: int, total: int, chunk: int, chunk_s, wall_s):
    """A chunk's metrics.jsonl record for lane ``i`` (None: a single run): the algorithm's counters, the
    evaluation, its other metrics as Python scalars, the chunk's steps per second and the wall time."""
    rec = algo.counters(iteration, total)
    rec.update({k: metrics[k] if i is None else metrics[k][i] for k in EVAL_KEYS})
    rec.update({k: v if i is None else v[i] for k, v in metrics.items() if k not in rec})
    rec = {k: v.item() if hasattr(v, "item") else v for k, v in rec.items()}
    steps = algo.counters(cfg.eval_every, chunk)
    rec["steps_per_s"] = (steps["env_steps"] + steps["select_steps"]) / max(chunk_s, 1e-9)
    rec["wall_s"] = wall_s
    return rec
