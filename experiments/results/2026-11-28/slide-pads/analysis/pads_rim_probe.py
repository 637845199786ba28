"""``slide_on_puck.py``'s press with the learnt policies' light press, in any direction, in our pads' Slide
(``finger=pads,finger_table=1,drive=weld,gripper_mass=22``) and in FetchSlide-v4 from the same start.

    PYTHONPATH=. python experiments/results/2026-11-28/slide-pads/analysis/pads_rim_probe.py \
        --press -0.25 --drag 0.5 --dirs +x,diag --offsets 0.015,0.02 --out OUT.json

The puck starts 0.04 + ``offset`` m from the grip home along the direction u; the gripper rises 0.1 m, moves 0.04 m
along u, comes down 0.1 m, presses with az = ``press`` for 4 steps, is dragged along u with |a_xy| = ``drag`` and
az = ``press`` for 8 steps, then with az = 0 for 8. Per run: the puck's centre ahead of the grip along u after
the press (``behind_at_press``: the reference's arm ends its approach a few mm short of ours), the grip's mean
height above the puck's centre while dragged (``dragging``; below 0.015 the pads slipped off beside it), the puck's
advance per step then, its advance by the end, the puck's largest tilt from the press to the drag's end and (the
reference) the pads' largest tilt while dragged; ``--trace``: those per step.
"""

from __future__ import annotations

import argparse
import gzip
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), *[".."] * 5))

OPTIONS = "finger=pads,finger_table=1,drive=weld,gripper_mass=22"
DIRS = {"+x": (1.0, 0.0), "+y": (0.0, 1.0), "-y": (0.0, -1.0), "diag": (0.7071, 0.7071)}


def task_options(support: str = "mjx", extra: str = "") -> dict:
    """Our Slide's options for the probes: the pads' on the puck ``support`` (MJX's plane needs no option; the polygon
    support left the package and is in git history at 56a0a5b), ``extra`` (k=v,...) replacing any of them."""
    from splid_jax.common.values import parse_overrides

    base = OPTIONS if support == "mjx" else f"{OPTIONS},puck_support={support}"
    return {**parse_overrides(base), **parse_overrides(extra)}


def read_json(path: str):
    """A probe's record, plain or gzip-compressed (``.gz``)."""
    with (gzip.open(path, "rt") if path.endswith(".gz") else open(path)) as fh:
        return json.load(fh)


def write_json(path: str, record, **dump) -> None:
    """A probe's record, gzip-compressed where ``path`` ends in ``.gz`` (the large per-turn records)."""
    with (gzip.open(path, "wt") if path.endswith(".gz") else open(path, "w")) as fh:
        json.dump(record, fh, **dump)


def actions(u, press: float, drag: float) -> list:
    ux, uy = u
    return ([(0, 0, 1, 0)] * 2 + [(0.6 * ux, 0.6 * uy, 0, 0)] * 2 + [(0, 0, -1, 0)] * 2 + [(0, 0, press, 0)] * 4
            + [(drag * ux, drag * uy, press, 0)] * 8 + [(drag * ux, drag * uy, 0, 0)] * 8)  # fmt: skip


def ours(env, step, u, offset: float, acts: list) -> np.ndarray:
    import jax
    import jax.numpy as jnp

    lay = env.layout
    s = env.reset(jax.random.PRNGKey(0))
    o = lay.object_q
    xy = jnp.asarray(lay.grip_home[:2]) + (0.04 + offset) * jnp.asarray(u, jnp.float32)
    s = env._state(s.physics.replace(qpos=s.physics.qpos.at[o : o + 2].set(xy)), s.desired_goal, jnp.int32(0),
                   jnp.bool_(False))  # fmt: skip
    out = [np.asarray(s.obs)]
    for a in acts:
        s = step(s, jnp.asarray(a, jnp.float32))
        out.append(np.asarray(s.obs))
    return np.array(out, np.float64)


def reference(env, u, offset: float, acts: list) -> tuple[np.ndarray, float]:
    import mujoco

    from splid_jax.reference.extra import make_reference
    from splid_jax.reference.mapping import reference_shift, reference_start

    r = make_reference("slide")
    r.reset(seed=0)
    m, d = r.unwrapped.model, r.unwrapped.data
    body = lambda i: mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, int(m.geom_bodyid[i])) or ""  # noqa: E731
    pad = next(i for i in range(m.ngeom) if "finger" in body(i))
    xy = np.asarray(env.layout.grip_home[:2]) + (0.04 + offset) * np.asarray(u)
    obs = reference_start(r, xy + reference_shift(env, r)[:2], np.asarray(r.unwrapped.goal))
    rot0 = d.geom_xmat[pad].reshape(3, 3).copy()
    out, tilt = [obs["observation"]], []
    for a in acts:
        obs, *_ = r.step(np.asarray(a, np.float64))
        out.append(obs["observation"])
        rel = d.geom_xmat[pad].reshape(3, 3) @ rot0.T
        tilt.append(float(np.degrees(np.arccos(min(1.0, rel[2, 2])))))
    r.close()
    return np.array(out, np.float64), max(tilt[9:18])


def measures(x: np.ndarray, u) -> dict:
    above = x[:, 2] - x[:, 5]
    along = (x[:, 3:5] - x[0, 3:5]) @ u
    return {
        "behind_at_press": round(float((x[10, 3:5] - x[10, 0:2]) @ u), 4),
        "dragging": round(float(above[11:19].mean()), 4),
        "drag_per_step": round(float(np.diff(along[10:19]).mean()), 4),
        "puck_moved": round(float(along[-1]), 4),
        "slipped": bool(above[11:19].mean() < 0.015),
        "puck_tilt_deg_max_pressed": round(float(np.degrees(np.hypot(x[6:19, 11], x[6:19, 12])).max()), 2),
    }


def trace(x: np.ndarray, u) -> dict:
    """Per control step 4 to 19 (lowered, pressed, dragged): the grip's height above the puck's centre, the puck's
    centre ahead of the grip along u and the puck's tilt (degrees)."""
    rows = slice(4, 20)
    return {
        "grip_above_puck": (x[rows, 2] - x[rows, 5]).round(4).tolist(),
        "puck_ahead": ((x[rows, 3:5] - x[rows, 0:2]) @ u).round(4).tolist(),
        "puck_tilt_deg": np.degrees(np.hypot(x[rows, 11], x[rows, 12])).round(2).tolist(),
    }


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--press", type=float, default=-0.25)
    p.add_argument("--drag", type=float, default=0.5)
    p.add_argument("--dirs", default="+x,diag")
    p.add_argument("--offsets", default="0.015,0.02,0.025")
    p.add_argument("--trace", action="store_true", help="also each step's height, offset and puck tilt")
    p.add_argument("--table", choices=("plane", "box"), default="plane", help="our table (the reference: box)")
    p.add_argument("--out", default=None)
    args = p.parse_args(argv)
    options = OPTIONS + (",table=box" if args.table == "box" else "")
    import jax

    import envs
    from splid_jax.common.values import parse_overrides
    from splid_jax.reference.extra import import_reference

    import_reference()
    env = envs.make("slide", **parse_overrides(options))
    step = jax.jit(env.step)
    rows = []
    for name in args.dirs.split(","):
        u = np.asarray(DIRS[name])
        acts = actions(u, args.press, args.drag)
        for offset in (float(v) for v in args.offsets.split(",")):
            x, tilt = reference(env, u, offset, acts)
            y = ours(env, step, u, offset, acts)
            row = {"dir": name, "offset": offset, "ours": measures(y, u),
                   "fetch": {**measures(x, u), "pad_tilt_deg_max_dragging": round(tilt, 2)}}  # fmt: skip
            if args.trace:
                row["ours"]["trace"], row["fetch"]["trace"] = trace(y, u), trace(x, u)
            rows.append(row)
            print(name, offset, " | ".join(f"{s}: {json.dumps(row[s])}" for s in ("ours", "fetch")), flush=True)
    if args.out:
        with open(args.out, "w") as fh:
            json.dump({"env_options": options, "press": args.press, "drag": args.drag, "rows": rows}, fh, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
