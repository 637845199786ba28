"""``python -m splid_jax.export RUN_DIR... --out DIR``: each run's policy, at a checkpoint, as a run directory
of its own without the relabel or replay buffer, small enough to copy off the machine that trained it and
evaluate elsewhere (``splid_jax.evaluate OUT/NAME --reference``, ``splid_jax.rollout OUT/NAME``).

A run's checkpoint holds its whole state, buffer included (a 5-seed Push sweep: tens of MB; HER: about 0.7 GB);
the exported one holds the policy and its normaliser, in the state of the same learner with a one-slot buffer.
Its config.json says so (``buffer_size`` 1, HER's ``buffer_transitions`` one episode), and export.json names
the run and checkpoint it came from; it evaluates, and is refused for ``--resume``."""

from __future__ import annotations

import argparse
import dataclasses
import errno
import os
import shutil
import sys
import tempfile
from collections.abc import Sequence

from splid_jax.cli import Parser, check_environment, exit_with, flag_error, quiet_interrupts, run_main
from splid_jax.common.errors import InvalidConfig, check
from splid_jax.common.paths import is_utf8, unwritable
from splid_jax.common.values import options_text
from splid_jax.runtime.run_files import EXPORT, METRICS, env_settings, write_json


def without_buffer(cfg, env):
    """``cfg`` with the smallest buffer its learner builds: the state keeps its layout but not the data."""
    from splid_jax.learners.her.config import HerConfig
    from splid_jax.learners.imitation.config import ImitationConfig

    settings = cfg.learner_config()
    if isinstance(settings, ImitationConfig):
        return dataclasses.replace(cfg, buffer_size=1, buffer_window=0, buffer_window_grow=0)
    if isinstance(settings, HerConfig):
        text = options_text(settings, buffer_transitions=env.episode_length)  # against HerConfig's own defaults
        return dataclasses.replace(cfg, her_options=text, her_defaults="mrl")
    return cfg  # ES keeps no buffer


def export(run_dir: str, out: str, step: int | None = None) -> dict:
    """Writes ``out`` (a new directory): config.json, the run's metrics, the policy at checkpoint ``step``
    (default: the newest) and export.json; returns export.json's record."""
    import jax

    from splid_jax.learners.registry import make_algorithm
    from splid_jax.reference.policy import restore_run
    from splid_jax.runtime import checkpoint

    check(not os.path.exists(out), "out", out, "a directory that does not exist yet (an export never overwrites)")
    cfg, env, _, state, step = restore_run(run_dir, step)
    small = dataclasses.replace(without_buffer(cfg, env), run_dir=out)
    like = make_algorithm(small, env).init(jax.random.PRNGKey(0))
    exported = like.replace(policy=state.policy)
    record = {"run_dir": os.path.abspath(run_dir), "step": int(step), "config": cfg.to_json()}
    parent = os.path.dirname(os.path.abspath(out))
    os.makedirs(parent, exist_ok=True)
    tmp = tempfile.mkdtemp(prefix=f".{os.path.basename(out)}.export-", dir=parent)
    try:  # written aside and renamed into place whole: a failed export leaves no half of one behind
        write_json(os.path.join(tmp, "config.json"), small.to_json())
        metrics = os.path.join(run_dir, METRICS)
        if os.path.isfile(metrics):
            shutil.copyfile(metrics, os.path.join(tmp, METRICS))
        checkpoint.save(tmp, step, exported, {"env": env_settings(env), "exported_from": record["run_dir"]})
        write_json(os.path.join(tmp, EXPORT), record)
        os.chmod(tmp, 0o777 & ~_umask())
        try:
            os.rename(tmp, out)
        except OSError as e:
            if e.errno not in (errno.EEXIST, errno.ENOTEMPTY, errno.EISDIR):
                raise
            why = "a directory that does not exist yet (another export wrote it meanwhile)"
            raise InvalidConfig("out", out, why) from None
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return record


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def build_parser() -> argparse.ArgumentParser:
    parser = Parser(prog="python -m splid_jax.export", description=__doc__.split("\n\n")[0])
    parser.add_argument("run_dirs", nargs="+", metavar="RUN_DIR", help="a run of train, or a member of a sweep")
    parser.add_argument("--out", required=True, metavar="DIR", help="the directory each run's export is written in")
    parser.add_argument("--step", type=int, default=None, help="the checkpoint (default: each run's newest)")
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    from splid_jax.reference.extra import EvaluationError
    from splid_jax.runtime.checkpoint import CheckpointError, is_no_space, write_failure

    parser = build_parser()
    ns = parser.parse_args(argv)
    names = [os.path.basename(os.path.abspath(d)) for d in ns.run_dirs]
    try:
        check(bool(ns.out.strip()), "out", ns.out, "a directory to write the exports in")
        check(is_utf8(ns.out), "out", ns.out, "a path of UTF-8 text (checkpoints are written under it)")
        why = unwritable(ns.out)  # a file, or a file on its way, fails here rather than after the first export
        check(why is None, "out", ns.out, f"a directory that can be made and written in ({why})")
        check(len(set(names)) == len(names), "run_dirs", " ".join(ns.run_dirs), "runs of distinct directory names")
        for run_dir, name in zip(ns.run_dirs, names, strict=True):
            record = export(run_dir, os.path.join(ns.out, name), ns.step)
            print(f"{run_dir} (iteration {record['step']}) -> {os.path.join(ns.out, name)}")
    except (InvalidConfig, EvaluationError, CheckpointError) as e:
        print(f"{parser.prog}: error: {flag_error(e, parser)}", file=sys.stderr)
        return 2
    except Exception as e:  # a full or read-only disk under --out: nothing of that export is left behind
        failure = write_failure(e)
        if failure is None:
            raise
        why = "no space left on the device" if is_no_space(e) else failure[1]
        print(f"python -m splid_jax.export: error: cannot write in {ns.out} ({why})", file=sys.stderr)
        return 3
    return 0


if __name__ == "__main__":
    quiet_interrupts("")
    check_environment()
    exit_with(run_main(main))
