"""``PYTHON -m splid_jax.reference.side RUN_DIR --out FILE.json``: the reference side of an evaluation alone, under the
MuJoCo of the interpreter that runs it. ``python -m splid_jax.evaluate RUN --reference --reference-python PYTHON``
calls it so: FetchSlide-v4 plays differently on the MuJoCo release gymnasium-robotics 1.4.2 supports (3.11.0) and on
the one our tasks run on (``extra.UNPATCHED_MUJOCO``), so its reference can run in an environment of its own."""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys


def loadable(cfg):
    """``cfg`` with a task this MuJoCo builds: Slide's pads' contact (its default) is checked on the kernels' release
    alone, and a policy of theirs takes the box fingers' inputs (nothing of our task is stepped here)."""
    import envs
    from envs.physics import kernels_checked
    from splid_jax.common.values import format_overrides, parse_overrides

    if cfg.env != "slide":
        return cfg
    options = parse_overrides(cfg.env_options)
    default = next(f.default for f in dataclasses.fields(envs.task_class(cfg.env)) if f.name == "finger")
    if options.get("finger", default) != "pads" or kernels_checked():
        return cfg
    options["finger"] = "box"
    options["hand_pitch"] = 0.0  # the pads' alone
    return dataclasses.replace(cfg, env_options=format_overrides(options))


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m splid_jax.reference.side", description=__doc__.split("\n\n")[0])
    p.add_argument("run_dir")
    p.add_argument("--episodes", type=int, required=True)
    p.add_argument("--seed", type=int, required=True)
    p.add_argument("--step", type=int, required=True)
    p.add_argument("--env-options", default="")
    p.add_argument("--eval-subgoal-reach", type=float, default=None)
    p.add_argument("--out", required=True)
    p.add_argument("--starts", default=None, help="an npz of mapping.save_starts: also run the reference from them")
    p.add_argument("--traces", default=None, help="where those episodes go (Episodes.save), with --starts")
    a = p.parse_args(argv)
    from splid_jax.reference.episodes import matched_reference
    from splid_jax.reference.extra import import_reference
    from splid_jax.reference.mapping import load_starts
    from splid_jax.reference.policy import load_run, policy_act, reference_here

    import_reference()
    cfg, env, policy, pstate, _ = load_run(a.run_dir, a.step, a.env_options, a.eval_subgoal_reach, adapt=loadable)
    fetch, ran_on = reference_here(cfg, policy, pstate, a.episodes, a.seed)
    if a.starts:
        act = policy_act(policy, pstate)
        matched_reference(env, cfg.env, act, load_starts(a.starts), a.seed).save(a.traces)
    with open(a.out, "w") as fh:
        json.dump({"fetch": fetch, "versions": ran_on}, fh)
    return 0


if __name__ == "__main__":
    sys.exit(main())
