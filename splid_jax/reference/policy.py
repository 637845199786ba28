"""A run's deterministic policy loaded from its checkpoint (a run of train, or a member of a sweep,
sliced out of the sweep's stacked checkpoint), and its evaluation in both simulators."""

from __future__ import annotations

import contextlib
import dataclasses
import io
import json
import os

import numpy as np

from splid_jax.reference.episodes import run_reference, summarise
from splid_jax.reference.extra import REFERENCE_IDS, EvaluationError, import_reference, reference_id, versions
from splid_jax.rollout import sweep_member  # noqa: F401  (named in the package's index)


def restore_run(run_dir: str, step: int | None = None, cfg=None):
    """(config, our task, algorithm, trained state, step) of the run in ``run_dir`` at checkpoint ``step``
    (default: the newest): a run of train, or a member of a sweep, of any task. ``cfg``: the run's config
    as the caller changed it (default: its config.json)."""
    from splid_jax.common.networks import PolicyState
    from splid_jax.rollout import load_config, load_trained

    if not os.path.isdir(run_dir):
        raise EvaluationError(f"{run_dir} is not a directory")
    cfg = load_config(run_dir) if cfg is None else cfg
    with contextlib.redirect_stdout(io.StringIO()):  # MJX prints a warp notice on import
        env, trainer, state, step = load_trained(cfg, step)
    if not isinstance(getattr(state, "policy", None), PolicyState):
        raise EvaluationError(f"the checkpoint of {run_dir} holds no policy (no networks.PolicyState at .policy)")
    return cfg, env, trainer, state, step


def load_run(run_dir: str, step: int | None = None, env_options: str = "", subgoal_reach: float | None = None,
             adapt=None):  # fmt: skip
    """(config, our task, the policy as the run's evaluations acted (``act(pstate, obs, goal)``, steered at
    subgoals where the run's ``eval_subgoal_reach`` says), its ``PolicyState``, step) of the run in ``run_dir``:
    a run of train, or a member of a sweep. ``env_options`` (``KEY=VALUE,...``) change our task's fields
    from the run's, e.g. ``table=box`` to put the reference's table edges in our task; ``subgoal_reach``
    replaces the run's ``eval_subgoal_reach``; ``adapt(config) -> config`` changes the config last."""
    from splid_jax.common.subgoals import steered
    from splid_jax.rollout import load_config

    if not os.path.isdir(run_dir):
        raise EvaluationError(f"{run_dir} is not a directory")
    cfg = load_config(run_dir)
    if env_options:
        cfg = dataclasses.replace(cfg, env_options=",".join(filter(None, (cfg.env_options, env_options))))
    if subgoal_reach is not None:
        cfg = dataclasses.replace(cfg, eval_subgoal_reach=subgoal_reach)
    cfg = cfg if adapt is None else adapt(cfg)
    reference_id(cfg.env)
    cfg, env, trainer, state, step = restore_run(run_dir, step, cfg)
    return cfg, env, steered(trainer.policy, env, cfg.eval_subgoal_reach), state.policy, step


def policy_act(policy, pstate):
    """The deterministic policy as ``act(obs, goal) -> action``, jitted, batched over leading axes."""
    import jax

    return jax.jit(lambda o, g: policy.act(pstate, o, g))


def evaluate(run_dir: str, episodes: int = 300, seed: int = 0, step: int | None = None, env_options: str = "",
             loaded: tuple | None = None, reference_python: str | None = None,
             side_traces: tuple[str, str] | None = None) -> dict:  # fmt: skip
    """The run's policy in the reference (its own resets, seeds ``seed`` ...) and in our task (the
    project's evaluation draw: ``rollout.rollout`` from ``PRNGKey(seed)``), ``episodes`` each.
    ``loaded``: what ``load_run`` gave, to load the checkpoint once. ``reference_python``: an interpreter
    whose environment runs the reference side (``splid_jax.reference.side``), on its own MuJoCo; ``side_traces``
    (starts npz, episodes npz): that side also runs the reference from the starts and writes its episodes."""
    import jax

    from splid_jax.rollout import rollout

    import_reference()  # a missing extra fails before any work
    cfg, env, policy, pstate, step = loaded or load_run(run_dir, step, env_options)
    states = jax.jit(lambda ps, k: rollout(env, policy, ps, k, episodes))(pstate, jax.random.PRNGKey(seed))
    succ = np.asarray(states.success[1:] & ~states.invalid[1:])
    dist = np.linalg.norm(np.asarray(states.achieved_goal[-1] - states.desired_goal[-1]), axis=-1)
    ours = summarise(succ.any(axis=0), succ[-1], dist)
    if reference_python:
        ref, ran_on = reference_side(reference_python, run_dir, episodes, seed, int(step), env_options, cfg,
                                     side_traces)  # fmt: skip
    else:
        ref, ran_on = reference_here(cfg, policy, pstate, episodes, seed)
    return {
        "run_dir": run_dir,
        "algo": cfg.algo,
        "task": cfg.env,
        "reference": REFERENCE_IDS[cfg.env],
        "step": int(step),
        "seed": seed,
        "env_options": cfg.env_options,
        "eval_subgoal_reach": cfg.eval_subgoal_reach,
        "ours": ours,
        "fetch": ref,
        "versions": ran_on,
    }


def reference_here(cfg, policy, pstate, episodes: int, seed: int) -> tuple[dict, dict]:
    """(the reference's summary, the releases it ran on) in this process."""
    return run_reference(cfg.env, policy_act(policy, pstate), episodes, seed).summary(), versions()


def reference_side(python: str, run_dir: str, episodes: int, seed: int, step: int, env_options: str, cfg,
                   side_traces: tuple[str, str] | None = None):  # fmt: skip
    """(the reference's summary, its versions) from ``python -m splid_jax.reference.side`` run by ``python``."""
    import subprocess
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "side.json")
        cmd = [python, "-m", "splid_jax.reference.side", run_dir, "--episodes", str(episodes), "--seed", str(seed),
               "--step", str(step), "--env-options", env_options, "--out", out]  # fmt: skip
        if cfg.eval_subgoal_reach is not None:
            cmd += ["--eval-subgoal-reach", repr(float(cfg.eval_subgoal_reach))]
        if side_traces is not None:
            cmd += ["--starts", side_traces[0], "--traces", side_traces[1]]
        quiet = {"stdin": subprocess.DEVNULL, "stdout": subprocess.DEVNULL}
        done = subprocess.run(cmd, stderr=subprocess.PIPE, text=True, **quiet)
        if done.returncode != 0:
            last = (done.stderr.strip().splitlines() or [f"exit code {done.returncode}"])[-1]
            raise EvaluationError(f"--reference-python {python}: its reference side failed: {last}")
        with open(out) as fh:
            side = json.load(fh)
    return side["fetch"], side["versions"]
