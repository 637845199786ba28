"""The light-press rim probe (``pads_rim_probe.py``: az -0.25, drag 0.5) with our pads' Slide on MJX's plane or, with
``--support polygon``, on MuJoCo C's puck support (``puck_support=polygon``: the package at 56a0a5b, where it lives)
beside FetchSlide-v4 from the same starts; per direction the first commanded offset that slipped and the puck's
largest tilt.

    PYTHONPATH=. python experiments/results/2026-11-28/slide-pads/analysis/pads_rim_probe_polygon.py \
        --support polygon --out experiments/results/2026-11-28/slide-pads/analysis/rim_probe_light_press_polygon.json.gz

``--yaws``: the puck also starts turned about its axis by each of these angles (degrees) in both simulators. A
turned cylinder is the same shape, but both colliders' choice of corners, decided by rounding, changes with it: the
share of turns that slipped per offset says how much of a single run's slip is that choice (``slip_share``).
``--upright``: both pucks start exactly upright (the reference's rests leaning by about 3e-6 rad).
"""

from __future__ import annotations

import argparse
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), *[".."] * 5))
sys.path.insert(0, os.path.dirname(__file__))

import pads_rim_probe as probe  # noqa: E402

OFFSETS = "0.0125,0.015,0.0175,0.02,0.0225,0.025,0.0275"


UPRIGHT = False  # --upright


def turned(quat, yaw_deg: float) -> np.ndarray:
    """Orientation ``quat`` (w, x, y, z) turned by ``yaw_deg`` about the world's z (``yaw_deg`` 0: ``quat`` as it
    is, bit for bit: the reference's resting puck leans by a few micro-radians, and which corners its collider
    keeps changes even with that)."""
    if UPRIGHT:
        quat = (1.0, 0.0, 0.0, 0.0)
    if yaw_deg == 0:
        return np.asarray(quat, np.float64)
    h = np.radians(yaw_deg) / 2
    w, x, y, z = np.asarray(quat, np.float64)
    c, s = np.cos(h), np.sin(h)
    return np.array([c * w - s * z, c * x - s * y, c * y + s * x, c * z + s * w])


def reference(env, u, offset: float, acts: list, yaw_deg: float) -> np.ndarray:
    """``pads_rim_probe.reference``'s run with the reference's puck turned by ``yaw_deg``."""
    import mujoco

    from splid_jax.reference.extra import make_reference
    from splid_jax.reference.mapping import reference_shift, reference_start

    r = make_reference("slide")
    r.reset(seed=0)
    m, d = r.unwrapped.model, r.unwrapped.data
    xy = np.asarray(env.layout.grip_home[:2]) + (0.04 + offset) * np.asarray(u)
    reference_start(r, xy + reference_shift(env, r)[:2], np.asarray(r.unwrapped.goal))
    j = int(m.jnt_qposadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, "object0:joint")])
    d.qpos[j + 3 : j + 7] = turned(d.qpos[j + 3 : j + 7], yaw_deg)
    mujoco.mj_forward(m, d)
    out = [r.unwrapped._get_obs()["observation"]]
    for a in acts:
        obs, *_ = r.step(np.asarray(a, np.float64))
        out.append(obs["observation"])
    r.close()
    return np.array(out, np.float64)


def ours(env, step, u, offset: float, acts: list, yaw_deg: float) -> np.ndarray:
    """``pads_rim_probe.ours``'s run with our puck turned by ``yaw_deg``."""
    import jax
    import jax.numpy as jnp

    lay = env.layout
    s = env.reset(jax.random.PRNGKey(0))
    o = lay.object_q
    xy = jnp.asarray(lay.grip_home[:2]) + (0.04 + offset) * jnp.asarray(u, jnp.float32)
    quat = turned(np.asarray(s.physics.qpos[o + 3 : o + 7]), yaw_deg)
    qpos = s.physics.qpos.at[o : o + 2].set(xy).at[o + 3 : o + 7].set(jnp.asarray(quat, s.physics.qpos.dtype))
    s = env._state(s.physics.replace(qpos=qpos), s.desired_goal, jnp.int32(0), jnp.bool_(False))
    out = [np.asarray(s.obs)]
    for a in acts:
        s = step(s, jnp.asarray(a, jnp.float32))
        out.append(np.asarray(s.obs))
    return np.array(out, np.float64)


def summary(rows: list, side: str) -> dict:
    """Per direction: the offsets that slipped (at any turn), the first, the share of turns that slipped per offset,
    and the largest tilt over the landing and press (trace
    steps 1 to 7) and from the press to the drag's end, over the offsets that held and all."""
    out = {}
    for d in sorted({r["dir"] for r in rows}):
        rr = [r[side] for r in rows if r["dir"] == d]
        offs = [r["offset"] for r in rows if r["dir"] == d]
        slipped = sorted({o for o, r in zip(offs, rr, strict=True) if r["slipped"]})
        share = {str(o): round(np.mean([r["slipped"] for o2, r in zip(offs, rr, strict=True) if o2 == o]), 3)
                 for o in sorted(set(offs))}  # fmt: skip
        out[d] = {
            "slipped": slipped,
            "first_slip": min(slipped) if slipped else None,
            "slip_share": share,
            "tilt_landing_press_max": max(max(r["trace"]["puck_tilt_deg"][1:8]) for r in rr),
            "tilt_pressed_max": max(r["puck_tilt_deg_max_pressed"] for r in rr),
            "tilt_pressed_max_held": max((r["puck_tilt_deg_max_pressed"] for r in rr if not r["slipped"]),
                                         default=None),
        }
    return out


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--dirs", default="diag,+x")
    p.add_argument("--offsets", default=OFFSETS)
    p.add_argument("--yaws", default="0", help="the puck's start turns about its axis (degrees), comma-separated")
    p.add_argument("--upright", action="store_true", help="both pucks start exactly upright")
    p.add_argument("--support", default="mjx", help="our puck_support (mjx: MJX's plane-cylinder contact)")
    p.add_argument("--env-options", default="", help="options for our Slide over the probe's (comma-separated k=v)")
    p.add_argument("--out", required=True)
    args = p.parse_args(argv)
    global UPRIGHT
    UPRIGHT = args.upright
    overrides = probe.task_options(args.support, args.env_options)
    options = ",".join(f"{k}={v}" for k, v in overrides.items())  # the later key wins
    import jax

    import envs
    from splid_jax.reference.extra import import_reference

    import_reference()
    env = envs.make("slide", **overrides)
    step = jax.jit(env.step)
    rows = []
    for name in args.dirs.split(","):
        u = np.asarray(probe.DIRS[name])
        acts = probe.actions(u, -0.25, 0.5)
        for offset in (float(v) for v in args.offsets.split(",")):
            for yaw in (float(v) for v in args.yaws.split(",")):
                x, y = reference(env, u, offset, acts, yaw), ours(env, step, u, offset, acts, yaw)
                row = {"dir": name, "offset": offset, "yaw_deg": yaw,
                       "ours": {**probe.measures(y, u), "trace": probe.trace(y, u)},
                       "fetch": {**probe.measures(x, u), "trace": probe.trace(x, u)}}  # fmt: skip
                rows.append(row)
                short = {s: {k: v for k, v in row[s].items() if k != "trace"} for s in ("ours", "fetch")}
                print(name, offset, yaw, json.dumps(short), flush=True)
    result = {"env_options": options, "press": -0.25, "drag": 0.5, "upright": args.upright,
              "summary": {"ours": summary(rows, "ours"), "fetch": summary(rows, "fetch")}, "rows": rows}  # fmt: skip
    print(json.dumps(result["summary"], indent=1))
    probe.write_json(args.out, result, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
