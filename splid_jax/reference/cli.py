"""``python -m splid_jax.evaluate RUN_DIR --reference`` (or ``--scripted TASK``): the command line,
its one-line errors (exit code 2) and the JSON it writes."""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import os
import sys

import numpy as np

from splid_jax.cli import Parser, flag_error
from splid_jax.common.errors import InvalidConfig
from splid_jax.common.paths import unwritable
from splid_jax.reference.episodes import Episodes, ours_from_starts, summarise
from splid_jax.reference.extra import EXTRA, REFERENCE_IDS, EvaluationError, import_reference, release_notice, versions
from splid_jax.reference.mapping import save_starts
from splid_jax.reference.policy import evaluate, load_run, policy_act
from splid_jax.reference.response import RESPONSE_KEYS, step_response
from splid_jax.reference.tracing import compare_slots, split_by_final, traces, traces_of
from splid_jax.runtime.run_files import write_atomic


def _folder(path: str) -> str:
    return os.path.dirname(os.path.abspath(path))


def write_result(path: str, obj) -> None:
    """The evaluation's JSON, replaced whole. Its folder was checked before the evaluation; made again if it was
    moved away while the episodes ran, so minutes of evaluation are not lost to a traceback."""
    os.makedirs(_folder(path), exist_ok=True)
    write_atomic(path, json.dumps(obj, indent=1))


def _line(name: str, s: dict) -> str:
    lo_a, hi_a = s["success_any_ci95"]
    lo_f, hi_f = s["success_final_ci95"]
    return (
        f"{name:22s} any {s['success_any']:.3f} [{lo_a:.3f}, {hi_a:.3f}]  final {s['success_final']:.3f} "
        f"[{lo_f:.3f}, {hi_f:.3f}]  median final distance {s['median_final_distance']:.3f} m"
    )


def build_parser() -> argparse.ArgumentParser:
    p = Parser(
        prog="python -m splid_jax.evaluate",
        description="Evaluate a run's deterministic policy in the reference simulator (Gymnasium-Robotics "
        "Fetch*-v4) and in our task, with 95 %% intervals.",
    )
    p.add_argument("run_dir", metavar="RUN_DIR", nargs="?", default=None)
    p.add_argument("--scripted", metavar="TASK", choices=sorted(REFERENCE_IDS), default=None,
                   help="instead of a run, the task's scripted controller (envs/fetch/scripted.py), from the same "
                   "starts and goals in both simulators: a check of the observation mapping")  # fmt: skip
    p.add_argument("--reference", action="store_true", help="run the policy in the matching Fetch*-v4 (needs "
                   f"{EXTRA})")  # fmt: skip
    p.add_argument("--episodes", type=int, default=300, help="episodes in each simulator (default: 300)")
    p.add_argument("--seed", type=int, default=0, help="seed of the episodes' starts and goals (default: 0)")
    p.add_argument("--step", type=int, default=None, help="checkpoint (iteration) to load (default: the newest)")
    p.add_argument("--env-options", default="", metavar="KEY=VALUE,...",
                   help="change our task's fields from the run's for its side of the comparison (e.g. table=box: "
                   "the reference's table, whose edges a pushed cube can fall off)")  # fmt: skip
    p.add_argument("--eval-subgoal-reach", type=float, default=None, metavar="M",
                   help="steer the policy at subgoals at most M from the achieved goal in both simulators, 0 not "
                   "at all (default: as the run's evaluations did, its eval_subgoal_reach)")  # fmt: skip
    p.add_argument("--out", default=None, metavar="FILE.json",
                   help="default: RUN_DIR/reference.json (with --scripted: scripted-TASK.json)")  # fmt: skip
    p.add_argument("--traces", default=None, metavar="FILE.npz",
                   help="also trace both simulators from the same starts and goals (distance to goal, object "
                   "speed, grip position per step) and the grip's response to a held action (this process's "
                   "MuJoCo; with --reference-python the reference's traces come from that interpreter's)")  # fmt: skip
    p.add_argument("--overwrite", action="store_true", help="replace an --out or --traces file that already exists")
    p.add_argument("--reference-python", default=None, metavar="PYTHON",
                   help="run the reference side under this interpreter, whose environment holds the package, "
                   "gymnasium-robotics and its own MuJoCo (FetchSlide-v4 plays differently on 3.11.0, the release "
                   "gymnasium-robotics 1.4.2 supports, and on ours); our side stays in this process")  # fmt: skip
    return p


def scripted(task: str, episodes: int, seed: int) -> tuple[dict, dict]:
    """The scripted controller of ``task`` from the same starts and goals in both simulators:
    (result, traces)."""
    import jax

    with contextlib.redirect_stdout(io.StringIO()):  # MJX prints a warp notice on import
        import envs
        from envs.fetch.scripted import CONTROLLERS
    import_reference()
    env = envs.make(task)
    act = CONTROLLERS[task]
    tr = traces(env, task, act, jax.jit(act), episodes, seed)
    result = {"scripted": task, "task": task, "reference": REFERENCE_IDS[task], "seed": seed}
    for sim in ("ours", "fetch"):
        succ, dist = tr[f"{sim}_success"], tr[f"{sim}_distance"][:, -1]
        result[sim] = summarise(succ.any(axis=1), succ[:, -1], dist)
    return result, tr


def traced_elsewhere(a, loaded) -> tuple[dict, dict]:
    """(result, traces) with the reference side under ``--reference-python``: our starts go to it as a file, its
    episodes from them come back as one, and ours are run here from the same starts."""
    import tempfile

    cfg, env, policy, pstate, _ = loaded
    starts, ours = ours_from_starts(env, lambda o, g: policy.act(pstate, o, g), a.episodes, a.seed)
    with tempfile.TemporaryDirectory() as tmp:
        paths = (os.path.join(tmp, "starts.npz"), os.path.join(tmp, "fetch.npz"))
        save_starts(paths[0], starts)
        result = evaluate(a.run_dir, a.episodes, a.seed, env_options=a.env_options, loaded=loaded,
                          reference_python=a.reference_python, side_traces=paths)  # fmt: skip
        ref = Episodes.load(paths[1])
    return result, traces_of(ours, ref, env.has_object)


def main(argv: list[str] | None = None) -> int:
    from splid_jax.runtime.checkpoint import CheckpointError

    p = build_parser()
    a = p.parse_args(argv)
    try:
        if not a.reference:
            raise EvaluationError("pass --reference (the evaluation in our task alone is what train reports)")
        if (a.run_dir is None) == (a.scripted is None):
            raise EvaluationError("give either RUN_DIR or --scripted TASK")
        if a.episodes < 1:
            raise EvaluationError(f"--episodes {a.episodes}: must be >= 1")
        if not 0 <= a.seed < 2**32:  # JAX's keys and Gymnasium's resets take no other
            raise EvaluationError(f"--seed {a.seed}: must be an integer in [0, 2**32)")
        if a.run_dir is not None and not os.path.isdir(a.run_dir):
            raise EvaluationError(f"{a.run_dir} is not a directory")
        if a.reference_python is not None:
            if a.scripted:
                raise EvaluationError("--reference-python: a run's evaluation alone (not with --scripted)")
            if not (os.path.isfile(a.reference_python) and os.access(a.reference_python, os.X_OK)):
                raise EvaluationError(f"--reference-python {a.reference_python}: not an executable file")
        out = a.out or (os.path.join(a.run_dir, "reference.json") if a.run_dir else f"scripted-{a.scripted}.json")
        for flag, path in (("--out", out), ("--traces", a.traces)):
            if path is not None and not os.path.isdir(_folder(path)):
                raise EvaluationError(f"{flag} {path}: its directory does not exist")
            why = None if path is None else unwritable(_folder(path))
            if why:  # said before the episodes, not after them
                raise EvaluationError(f"{flag} {path}: its directory cannot be written in ({why})")
            if path is not None and os.path.exists(path) and not a.overwrite:  # an earlier evaluation's
                raise EvaluationError(f"{flag} {path}: already exists (pass --overwrite to replace it)")
        if a.scripted:
            result, tr = scripted(a.scripted, a.episodes, a.seed)
            title = f"the scripted {a.scripted} controller, the same {a.episodes} starts in each"
        else:
            import_reference()  # a missing extra fails before the checkpoint is read
            loaded = load_run(a.run_dir, a.step, a.env_options, a.eval_subgoal_reach)
            if a.traces and a.reference_python:
                result, tr = traced_elsewhere(a, loaded)
            else:
                result = evaluate(a.run_dir, a.episodes, a.seed, env_options=a.env_options, loaded=loaded,
                                  reference_python=a.reference_python)  # fmt: skip
                if a.traces:
                    cfg, env, policy, pstate, _ = loaded
                    pol = lambda o, g: policy.act(pstate, o, g)  # noqa: E731
                    tr = traces(env, cfg.env, pol, policy_act(policy, pstate), a.episodes, a.seed)
            what = f"{result['algo']} on {result['task']}, iteration {result['step']}"
            title = f"{a.run_dir} ({what}), {a.episodes} episodes each"
    except (EvaluationError, InvalidConfig, CheckpointError) as err:
        print(f"{p.prog}: error: {flag_error(err, p)}", file=sys.stderr)
        return 2
    result.setdefault("versions", versions())
    print(title + ":")
    print(_line("ours (MJX)", result["ours"]))
    print(_line(result["reference"], result["fetch"]))
    notice = release_notice(result.get("task", ""), result["versions"]["mujoco"])
    if notice:
        print(notice)
    if a.traces:
        import envs

        resp = step_response(envs.make(result["task"]), result["task"])
        os.makedirs(_folder(a.traces), exist_ok=True)
        np.savez_compressed(a.traces, **tr, **{f"response_{k}": np.asarray(resp[k]) for k in RESPONSE_KEYS})
        result["traces"] = {"file": a.traces, "ours": split_by_final(tr, "ours"), "fetch": split_by_final(tr, "fetch")}
        result["step_response"] = resp
        result["slots"] = compare_slots(tr["ours_obs"], tr["fetch_obs"])
        print(f"traces: {a.traces} (same starts and goals in both; by final-step outcome in the JSON)")
    write_result(out, result)
    print(f"wrote {out}")
    return 0
