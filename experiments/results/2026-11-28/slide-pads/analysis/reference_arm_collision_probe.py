"""The reference's light-press rim probe (``pads_rim_probe.py``'s actions and measures) in FetchSlide-v4 as it is, or
with every robot geom but the two finger pads made non-colliding (contype = conaffinity = 0): does the reference's
slip near the rim come from the arm chain's dynamics or from the arm meshes' contacts?

    PYTHONPATH=. python experiments/results/2026-11-28/slide-pads/analysis/reference_arm_collision_probe.py \
        --modes as_is,no_arm_collisions --dirs +x,diag --offsets 0.0125,0.015,0.0175,0.02,0.0225,0.025,0.0275 \
        [--yaws 0,2.5,5,7.5,10,12.5,15,17.5] --out OUT.json

``--yaws``: the puck also starts turned about its axis by each of these angles (``pads_rim_probe_polygon.py``'s
turns): a single run near the rim is one draw of C's corner choice, the share over the turns the measure.

Per run, beside the probe's measures: ``arm_contacts``, the contacts in which a robot geom other than a pad took
part, summed over the run's substeps (each geom pair's count), and the gripper link's largest tilt while dragged.
"""

from __future__ import annotations

import argparse
import json
import os
import sys

import mujoco
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.join(HERE, *[".."] * 5)]

from pads_rim_probe import DIRS, actions, measures, trace, write_json  # noqa: E402
from pads_rim_probe_polygon import turned  # noqa: E402

PADS = ("robot0:r_gripper_finger_link", "robot0:l_gripper_finger_link")


def robot_geoms(m: mujoco.MjModel) -> list[int]:
    """The geoms on robot bodies (the mocap's excepted) other than the finger pads."""
    out = []
    for i in range(m.ngeom):
        body = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, int(m.geom_bodyid[i])) or ""
        if body.startswith("robot0:") and body != "robot0:mocap" and body not in PADS:
            out.append(i)
    return out


BASE_SLIDES = ("robot0:slide0", "robot0:slide1", "robot0:slide2")


def recompiled(r, base: str) -> tuple[mujoco.MjModel, mujoco.MjData]:
    """FetchSlide-v4 ``r`` (reset) recompiled with its base ``fixed`` (welded where its three slides hold it, the
    slides removed) or ``held`` (the slides kept, each held at its place by a joint equality, the soft hold the
    floor contact gave in the constraint solver), its state copied joint by joint; the env then steps the new
    model."""
    e = r.unwrapped
    m, d = e.model, e.data
    spec = mujoco.MjSpec.from_file(e.fullpath)
    if base == "fixed":
        body = spec.body("robot0:base_link")
        body.pos = [p + d.qpos[m.joint(j).qposadr[0]] for p, j in zip(body.pos, BASE_SLIDES, strict=True)]
        for j in BASE_SLIDES:
            spec.delete(spec.joint(j))
    else:
        for j in BASE_SLIDES:
            eq = spec.add_equality(type=mujoco.mjtEq.mjEQ_JOINT, name1=j, objtype=mujoco.mjtObj.mjOBJ_JOINT)
            eq.data[0] = d.qpos[m.joint(j).qposadr[0]]
    m2 = spec.compile()
    m2.eq_data[0] = m.eq_data[0]  # the env's reset_mocap_welds (the weld comes first)
    d2 = mujoco.MjData(m2)
    for j in range(m2.njnt):
        name = m2.joint(j).name
        nq = {0: 7, 1: 4}.get(int(m2.jnt_type[j]), 1)
        nv = {0: 6, 1: 3}.get(int(m2.jnt_type[j]), 1)
        a, b = m.joint(name).qposadr[0], m.joint(name).dofadr[0]
        d2.qpos[m2.jnt_qposadr[j] : m2.jnt_qposadr[j] + nq] = d.qpos[a : a + nq]
        d2.qvel[m2.jnt_dofadr[j] : m2.jnt_dofadr[j] + nv] = d.qvel[b : b + nv]
    d2.mocap_pos[:], d2.mocap_quat[:], d2.time = d.mocap_pos, d.mocap_quat, d.time
    mujoco.mj_forward(m2, d2)
    e.model, e.data = m2, d2
    e._model_names = e._utils.MujocoModelNames(m2)
    return m2, d2


def run(env, u, offset: float, acts: list, mode: str, yaw_deg: float = 0.0) -> dict:
    """One probe run in FetchSlide-v4 (``mode``: as_is, or ``+``-joined no_arm_collisions and fixed_base
    or held_base); the
    probe's measures and trace."""
    from splid_jax.reference.extra import make_reference
    from splid_jax.reference.mapping import reference_shift, reference_start

    r = make_reference("slide")
    r.reset(seed=0)
    m, d = r.unwrapped.model, r.unwrapped.data
    if "fixed_base" in mode or "held_base" in mode:
        m, d = recompiled(r, "fixed" if "fixed_base" in mode else "held")
    arm = robot_geoms(m)
    if "no_arm_collisions" in mode:
        m.geom_contype[arm] = 0
        m.geom_conaffinity[arm] = 0
    arm_set = set(arm)
    xy = np.asarray(env.layout.grip_home[:2]) + (0.04 + offset) * np.asarray(u)
    obs = reference_start(r, xy + reference_shift(env, r)[:2], np.asarray(r.unwrapped.goal))
    if yaw_deg:
        j = int(m.joint("object0:joint").qposadr[0])
        d.qpos[j + 3 : j + 7] = turned(d.qpos[j + 3 : j + 7], yaw_deg)
        mujoco.mj_forward(m, d)
        obs = r.unwrapped._get_obs()
    link = m.body("robot0:gripper_link").id
    rot0 = d.xmat[link].reshape(3, 3).copy()
    out, tilt, pairs = [obs["observation"]], [], {}
    sim = r.unwrapped
    for a in acts:
        sim._set_action(np.asarray(a, np.float64))
        for _ in range(sim.n_substeps):  # the env's own step, substep by substep, to count contacts as they occur
            mujoco.mj_step(m, d)
            for c in d.contact[: d.ncon]:
                g1, g2 = int(c.geom1), int(c.geom2)
                if g1 in arm_set or g2 in arm_set:
                    key = " / ".join(
                        sorted(mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_GEOM, g) or str(g) for g in (g1, g2))
                    )
                    pairs[key] = pairs.get(key, 0) + 1
        sim._step_callback()
        out.append(sim._get_obs()["observation"])
        rel = d.xmat[link].reshape(3, 3) @ rot0.T
        tilt.append(float(np.degrees(np.arccos(min(1.0, rel[2, 2])))))
    r.close()
    x = np.array(out, np.float64)
    return {**measures(x, u), "link_tilt_deg_max_dragging": round(max(tilt[9:18]), 2), "arm_contacts": pairs,
            "trace": trace(x, u)}  # fmt: skip


def summary(rows: list) -> dict:
    """Per mode and direction: the slips per offset over the turns and the first offset that slipped at any turn."""
    out = {}
    for mode in dict.fromkeys(r["mode"] for r in rows):
        for d in dict.fromkeys(r["dir"] for r in rows):
            rr = [r for r in rows if r["mode"] == mode and r["dir"] == d]
            offs = sorted({r["offset"] for r in rr})
            slips = [sum(r["slipped"] for r in rr if r["offset"] == o) for o in offs]
            out[f"{mode} {d}"] = {
                "offsets": offs,
                "slips_per_offset": slips,
                "runs_per_offset": len(rr) // len(offs),
                "first_slip": min((o for o, n in zip(offs, slips, strict=True) if n), default=None),
            }
    return out


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--modes", default="as_is,no_arm_collisions")
    p.add_argument("--press", type=float, default=-0.25)
    p.add_argument("--drag", type=float, default=0.5)
    p.add_argument("--dirs", default="+x,diag")
    p.add_argument("--offsets", default="0.0125,0.015,0.0175,0.02,0.0225,0.025,0.0275")
    p.add_argument("--yaws", default="0", help="the puck's start turns about its axis (degrees), comma-separated")
    p.add_argument("--out", default=None)
    args = p.parse_args(argv)
    from pads_rim_probe import OPTIONS

    import envs
    from splid_jax.common.values import parse_overrides
    from splid_jax.reference.extra import import_reference

    import_reference()
    env = envs.make("slide", **parse_overrides(OPTIONS))
    rows = []
    for mode in args.modes.split(","):
        for name in args.dirs.split(","):
            u = np.asarray(DIRS[name])
            acts = actions(u, args.press, args.drag)
            for offset in (float(v) for v in args.offsets.split(",")):
                for yaw in (float(v) for v in args.yaws.split(",")):
                    res = run(env, u, offset, acts, mode, yaw)
                    rows.append({"mode": mode, "dir": name, "offset": offset, "yaw_deg": yaw, **res})
                    short = {k: v for k, v in res.items() if k != "trace"}
                    print(mode, name, offset, yaw, json.dumps(short), flush=True)
    result = {"press": args.press, "drag": args.drag, "summary": summary(rows), "rows": rows}
    print(json.dumps(result["summary"]))
    if args.out:
        write_json(args.out, result, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
