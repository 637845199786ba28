"""Our pads' Slide (``finger=pads,finger_table=1,drive=weld,gripper_mass=22``) in MuJoCo C with its gripper on the
reference's arm (``fetch_arm.py``: the 7-joint chain, the 6-dof mocap weld on the gripper link, no arm
collisions; the base ``held`` as the reference's or ``fixed``), or as it is (``--arm none``: the rigid gripper on
three slides, ``pads_rim_probe_c.py``'s model), on our plane table or (``--table box``) the reference's box: the
light-press rim probe over the puck's start turns, the press
probes and the scripted strike.

    PYTHONPATH=. python experiments/results/2026-11-28/slide-pads/analysis/slide_arm_c.py --arm held \
        --yaws 0,2.5,5,7.5,10,12.5,15,17.5 --strike 200 --out OUT.json.gz

Each control step sets the grip target as the task does (``control.gripper_target`` from the grip site); on the arm
the mocap body then goes where the reference's ``mocap_set_action`` puts it (``arm.mocap_target``).
"""

from __future__ import annotations

import argparse
import json
import os
import sys

import mujoco
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.join(HERE, *[".."] * 5)
sys.path[:0] = [HERE, ROOT, os.path.join(ROOT, "experiments", "reference")]

import pads_rim_probe as probe  # noqa: E402
from pads_rim_probe_c import box_table, c_observation  # noqa: E402
from pads_rim_probe_polygon import turned  # noqa: E402

OPTIONS = {"finger": "pads", "finger_table": 1.0, "drive": "weld", "gripper_mass": 22.0}


class Sim:
    """One model: ``reset`` to a puck start, ``step`` one control step of an action, ``obs`` the 25 floats' grip,
    puck, relative position, tilt and velocities."""

    def __init__(self, arm: str, timestep: float | None = None, substeps: int | None = None, table: str = "plane",
                 fingers: str = "fixed"):  # fmt: skip
        import fetch_arm

        from envs.fetch import control, models
        from envs.fetch.tasks import Slide

        task = Slide(**OPTIONS)
        opts = task.model_options()
        if timestep:
            opts["timestep"] = timestep
        xml = models.mjcf("slide", **opts)
        xml = box_table(xml) if table == "box" else xml
        self.arm = arm
        self.m = mujoco.MjModel.from_xml_string(xml if arm == "none" else fetch_arm.mjcf(xml, arm, fingers))
        self.fingers = [] if arm == "none" or fingers == "fixed" else list(fetch_arm.FINGER_HOME)
        self.substeps = substeps or round(task.timestep * task.substeps / self.m.opt.timestep)
        self.dt = self.m.opt.timestep * self.substeps
        self.o = int(self.m.joint("object").qposadr[0])
        self.ov = int(self.m.joint("object").dofadr[0])
        self.site = self.m.site("grip").id
        self.home = np.asarray(models._SCENES["slide"][2])
        self.lo, self.hi = models.workspace_box("slide", OPTIONS["finger_table"])
        self.center = control.ARM_REACH_CENTER["slide"]
        self.gripper_target = control.gripper_target
        if arm != "none":
            self.link = self.m.body("robot0:gripper_link").id
            self.mocap_target = fetch_arm.mocap_target
        self.rest_z = models.rest_height(self.m, self.o) if arm == "none" else self._rest_z()
        self.jac = np.zeros((3, self.m.nv))

    def _rest_z(self) -> float:
        """The puck's rest height on our table (the arm held at its start meanwhile does not touch it)."""
        d = self.reset((self.home[0] + 0.2, self.home[1] + 0.2), 0.0, rest_z=0.42)
        for _ in range(round(1.0 / self.m.opt.timestep)):
            mujoco.mj_step(self.m, d)
        return float(d.qpos[self.o + 2])

    def reset(self, xy, yaw_deg: float = 0.0, rest_z: float | None = None) -> mujoco.MjData:
        import fetch_arm

        m = self.m
        d = mujoco.MjData(m)
        d.qpos[self.o : self.o + 7] = [*xy, rest_z or self.rest_z, *turned((1, 0, 0, 0), yaw_deg)]
        if self.arm != "none":
            for name, (q, v) in [*fetch_arm.HOME.items(), *((f, fetch_arm.FINGER_HOME[f]) for f in self.fingers)]:
                d.qpos[m.joint(name).qposadr[0]], d.qvel[m.joint(name).dofadr[0]] = q, v
            mujoco.mj_kinematics(m, d)
            d.mocap_pos[0], d.mocap_quat[0] = d.xpos[self.link], d.xquat[self.link]
        mujoco.mj_forward(m, d)
        return d

    def step(self, d: mujoco.MjData, action) -> None:
        mujoco.mj_kinematics(self.m, d)
        grip = d.site_xpos[self.site].copy()
        target = self.home + self.gripper_target(grip - self.home, np.asarray(action[:3], float), self.home,
                                                 self.lo, self.hi, self.center)  # fmt: skip
        if self.arm == "none":
            d.mocap_pos[0] = target
        else:
            d.mocap_pos[0], d.mocap_quat[0] = self.mocap_target(target, d.xpos[self.link], grip, d.xquat[self.link])
        for _ in range(self.substeps):
            mujoco.mj_step(self.m, d)
        for f in self.fingers:  # the reference's block_gripper: its finger slides put back closed each step
            d.qpos[self.m.joint(f).qposadr[0]] = 0.0

    def obs(self, d: mujoco.MjData) -> np.ndarray:
        x = c_observation(self.m, d, self.site, self.o)
        mujoco.mj_jacSite(self.m, d, self.jac, None, self.site)
        gv = (self.jac @ d.qvel) * self.dt
        x[14:17] = d.qvel[self.ov : self.ov + 3] * self.dt - gv
        x[20:23] = gv
        return x

    def puck(self, d: mujoco.MjData) -> np.ndarray:
        return d.qpos[self.o : self.o + 3].copy()

    def run(self, xy, acts, yaw_deg: float = 0.0) -> np.ndarray:
        d = self.reset(xy, yaw_deg)
        out = [self.obs(d)]
        for a in acts:
            self.step(d, a)
            out.append(self.obs(d))
        return np.array(out)


class Reference(Sim):
    """FetchSlide-v4 itself behind ``Sim``'s calls (its own reset, step and observation; positions moved into our
    coordinates), to run the same starts and loops."""

    def __init__(self, arm_collisions: bool = True):
        import envs
        from envs.fetch import models
        from splid_jax.common.values import parse_overrides
        from splid_jax.reference.extra import import_reference, make_reference
        from splid_jax.reference.mapping import reference_shift

        import_reference()
        self.env = make_reference("slide")
        self.env.reset(seed=0)
        if not arm_collisions:  # every robot geom but the pads (in the probes, the base on the floor alone)
            from reference_arm_collision_probe import robot_geoms

            m = self.env.unwrapped.model
            m.geom_contype[robot_geoms(m)] = m.geom_conaffinity[robot_geoms(m)] = 0
        ours = envs.make("slide", **parse_overrides(",".join(f"{k}={v}" for k, v in OPTIONS.items())))
        self.shift = reference_shift(ours, self.env)
        self.home = np.asarray(models._SCENES["slide"][2])
        self.rest_z = float(self.env.unwrapped.height_offset) - self.shift[2]

    def reset(self, xy, yaw_deg: float = 0.0, rest_z: float | None = None):
        from splid_jax.reference.mapping import reference_start

        e = self.env.unwrapped
        self.env.reset(seed=0)
        reference_start(self.env, np.asarray(xy) + self.shift[:2], np.asarray(e.goal))
        j = int(e.model.joint("object0:joint").qposadr[0])
        e.data.qpos[j + 3 : j + 7] = turned(e.data.qpos[j + 3 : j + 7], yaw_deg)
        mujoco.mj_forward(e.model, e.data)
        return self.env

    def step(self, env, action) -> None:
        env.step(np.asarray(action, np.float64))

    def obs(self, env) -> np.ndarray:
        x = env.unwrapped._get_obs()["observation"].copy()
        x[0:3] -= self.shift
        x[3:6] -= self.shift
        return x

    def puck(self, env) -> np.ndarray:
        return self.obs(env)[3:6]


def rim(sim: Sim, dirs: str, offsets: str, yaws: str) -> dict:
    """The light press (az -0.25, drag 0.5) per direction, offset and start turn: ``pads_rim_probe.py``'s measures."""
    rows = []
    for name in dirs.split(","):
        u = np.asarray(probe.DIRS[name])
        acts = probe.actions(u, -0.25, 0.5)
        for offset in map(float, offsets.split(",")):
            for yaw in map(float, yaws.split(",")):
                x = sim.run(sim.home[:2] + (0.04 + offset) * u, acts, yaw)
                rows.append({"dir": name, "offset": offset, "yaw_deg": yaw, **probe.measures(x, u),
                             "trace": probe.trace(x, u)})  # fmt: skip
    summary = {}
    for name in dirs.split(","):
        offs = sorted({r["offset"] for r in rows if r["dir"] == name})
        slips = [sum(r["slipped"] for r in rows if r["dir"] == name and r["offset"] == o) for o in offs]
        held = [r for r in rows if r["dir"] == name and not r["slipped"]]
        summary[name] = {"offsets": offs, "slips_per_offset": slips,
                         "first_slip": min((o for o, n in zip(offs, slips, strict=True) if n), default=None),
                         "grip_above_puck_dragging_held": round(float(np.median([r["dragging"] for r in held])), 4)
                         if held else None,
                         "drag_per_step_held": round(float(np.median([r["drag_per_step"] for r in held])), 4)
                         if held else None}  # fmt: skip
    return {"summary": summary, "rows": rows}


def press(sim: Sim) -> dict:
    """``slide_press_probes.py``'s press (az -1) at 0, 0.01 and 0.02 behind the centre along +x."""
    import slide_on_puck
    import slide_press_probes

    out = {}
    for offset in slide_press_probes.OFFSETS:
        x = sim.run(sim.home[:2] + np.array([0.04 + offset, 0.0]), slide_on_puck.ACTIONS)
        out[str(offset)] = slide_press_probes.measures(x[:, :6])
    return out


def strike(sim: Sim, episodes: int, seed: int = 0) -> dict:
    """The scripted strike (``envs.fetch.scripted.slide``) from ``run_ours.py``'s starts, as
    ``slide_press_probes.strike_stats``."""
    import jax
    import slide_press_probes

    sys.path.insert(0, os.path.join(ROOT, "experiments", "parity"))
    import slide_c

    from envs.fetch import scripted

    obj_xy, goal_xy = slide_c.starts(episodes, seed)
    ctl = jax.jit(scripted.slide)
    records = []
    for i in range(episodes):  # one at a time: the reference steps one env
        d = sim.reset(obj_xy[i])
        goal = np.array([*goal_xy[i], sim.rest_z])
        succ = []
        for _ in range(50):
            act = np.clip(np.asarray(ctl(sim.obs(d).astype(np.float32), goal.astype(np.float32)), float), -1, 1)
            sim.step(d, act)
            succ.append(np.linalg.norm(sim.puck(d) - goal) < 0.05)
        v, disp = goal_xy[i] - obj_xy[i], sim.puck(d)[:2] - obj_xy[i]
        n = float(np.linalg.norm(v))
        across = float(abs(disp[0] * v[1] - disp[1] * v[0]) / n)
        records.append({"success_any": bool(any(succ)), "success_final": bool(succ[-1]),
                        "along": float(disp @ v / n - n), "across": across})  # fmt: skip
    return slide_press_probes.strike_stats(records)


def free(sim: Sim) -> dict:
    """The light probe's diagonal actions with the puck 0.3 m aside and the pads kept in the air (no contact): per
    control step the grip's distance (mm) from FetchSlide-v4's under the same actions."""
    u = np.asarray(probe.DIRS["diag"])
    acts = [(0, 0, 0, 0) if i == 4 else a for i, a in enumerate(probe.actions(u, -0.25, 0.5))]
    xy = sim.home[:2] + 0.04 * u + np.array([0.0, 0.3])
    ours, ref = sim.run(xy, acts), Reference().run(xy, acts)
    return {"grip_from_reference_mm": (1000 * np.abs(ours[:, 0:3] - ref[:, 0:3]).max(axis=1)).round(2).tolist()}


def summarise(paths: list[str]) -> None:
    """One markdown row per result file: first slip +x / diag and the slips per offset over the turns, the grip's
    height above the puck's centre and the drag per step (light press, held runs; the press at 0 and 0.01 behind the
    centre), the strike's success and median landing."""
    for path in paths:
        r = probe.read_json(path)
        rim_, pr, st = r.get("rim", {}).get("summary", {}), r["press"], r.get("strike")
        slips = " / ".join(f"{rim_[d]['first_slip']} ({' '.join(map(str, rim_[d]['slips_per_offset']))})" for d in rim_)
        light = " / ".join(f"{rim_[d]['grip_above_puck_dragging_held']}, {rim_[d]['drag_per_step_held']}" for d in rim_)
        hard = " / ".join(f"{pr[k]['grip_on_puck']}, {pr[k]['drag_per_step']}" for k in ("0.0", "0.01"))
        strike_ = f"{st['success_any']} / {st['success_final']}; {st['along_q10_25_50_75_90'][2]}" if st else ""
        print(f"| {os.path.basename(path)} | {slips} | {light} | {hard} | {strike_} |")


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument(
        "--arm",
        choices=("none", "held", "fixed", "reference", "reference-no-arm-collisions"),
        default="held",
        help="reference: FetchSlide-v4 itself through the same loops (no-arm-collisions: its robot geoms but the pads"
        " not colliding)",
    )
    p.add_argument("--dirs", default="+x,diag")
    p.add_argument("--offsets", default="0.0125,0.015,0.0175,0.02,0.0225,0.025,0.0275")
    p.add_argument("--yaws", default="0")
    p.add_argument("--no-rim", action="store_true")
    p.add_argument("--strike", type=int, default=0, metavar="N")
    p.add_argument("--free", action="store_true", help="also the grip's path in the air against the reference's")
    p.add_argument("--timestep", type=float, default=None)
    p.add_argument("--substeps", type=int, default=None)
    p.add_argument("--table", choices=("plane", "box"), default="plane", help="box: the reference's table box")
    p.add_argument("--fingers", choices=("fixed", "jointed"), default="fixed", help="the pads on the finger slides")
    p.add_argument("--out", default=None)
    p.add_argument("--summarise", nargs="+", metavar="JSON", help="only print the rows of these result files")
    args = p.parse_args(argv)
    if args.summarise:
        summarise(args.summarise)
        return 0
    if args.arm.startswith("reference"):
        sim, result = Reference(args.arm == "reference"), {"arm": args.arm}
    else:
        sim = Sim(args.arm, args.timestep, args.substeps, args.table, args.fingers)
        result = {"arm": args.arm, "options": OPTIONS, "timestep": sim.m.opt.timestep, "substeps": sim.substeps,
                  "table": args.table, "fingers": args.fingers}  # fmt: skip
    if not args.no_rim:
        result["rim"] = rim(sim, args.dirs, args.offsets, args.yaws)
        print("rim", json.dumps(result["rim"]["summary"]), flush=True)
    result["press"] = press(sim)
    print("press", json.dumps(result["press"]), flush=True)
    if args.free:
        result["free"] = free(sim)
        print("free", json.dumps(result["free"]), flush=True)
    if args.strike:
        result["strike"] = strike(sim, args.strike)
        print("strike", json.dumps(result["strike"]), flush=True)
    if args.out:
        probe.write_json(args.out, result, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
