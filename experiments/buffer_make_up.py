"""What a sweep's relabel buffers hold at its latest checkpoint, per member: the share of pairs whose goal is
where the object already is (held goals, those that teach staying on a reached goal), of goals and states
lifted above the object's resting height, and how far the other goals lie (``final_step.buffer_make_up``).

    python experiments/buffer_make_up.py SWEEP_DIR [--out FILE.json]

Run it on a checkpoint kept at the peak and on a later one to see whether what the buffer teaches changed."""

from __future__ import annotations

import argparse
import json
import os

import jax
import numpy as np
from final_step import buffer_make_up

from splid_jax.reference.policy import restore_sweep


def make_up(sweep_dir: str) -> dict:
    env, _, state, step, _ = restore_sweep(sweep_dir)
    with open(os.path.join(sweep_dir, "sweep.json")) as fh:
        members = [m.get("run_dir") for m in json.load(fh)["members"]]
    rows = jax.device_get(jax.vmap(lambda b: buffer_make_up(env, b))(state.buffer))
    return {
        "sweep": os.path.abspath(sweep_dir),
        "iteration": int(step),
        "members": members,
        **{k: np.asarray(v, np.float64).round(4).tolist() for k, v in rows.items()},
    }


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("sweep_dir")
    p.add_argument("--out", default=None)
    a = p.parse_args(argv)
    result = make_up(a.sweep_dir)
    print(json.dumps(result))
    if a.out:
        with open(a.out, "w") as fh:
            json.dump(result, fh, indent=1)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
