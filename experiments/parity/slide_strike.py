"""Slide's strike, measured on both sides: why ours and the reference differ at the final step.

The scripted slide (``envs/fetch/scripted.py``) closes in on the puck slowly, then pushes at the
launch speed from which friction alone stops the puck on the goal; the puck leaves the fingers faster
than the gripper moves and glides. A puck that stops short is pushed again, one that glides past the
goal cannot be pulled back. So final-step success hinges on the mean launch speed against the wanted
one. Per episode this records, at MuJoCo-step resolution:

- ``want``: the wanted launch speed (``scripted.launch_velocity`` of the start-to-goal displacement);
- ``v_grip``: the grip site's speed along the launch line at the first finger-puck contact;
- ``v_puck``: the puck's peak speed along that line; ``strikes``: finger-puck contacts begun;
- ``along`` / ``across``: where the puck ends, along the start-to-goal line (past the goal > 0) and off it.

It also records the free-space drive response: the grip site's speed every 4 ms after the gripper
target jumps 4.5 cm ahead of a gripper that was closing in at 0.2 m/s (the puck moved out of reach).

    # the reference (its own environment, see README.md)
    experiments/parity/.venv-ref/bin/python experiments/parity/slide_strike.py --side reference \\
        --episodes 200 --out experiments/parity/results/strike_reference.json
    # ours: our Slide MJCF, reset, control step and controller in MuJoCo C (``slide_c.py``)
    python experiments/parity/slide_strike.py --side ours --episodes 200 \
        --out experiments/parity/results/strike_ours.json
    # ours under other drives and gripper masses (each a model option of ``envs.fetch.models.mjcf``)
    python experiments/parity/slide_strike.py --side ours --grid --out experiments/parity/results/strike_grid.json
    # ours under the reference's drive law (a weld-like constraint to a mocap target), at 4 ms and at 2 ms
    python experiments/parity/slide_strike.py --side ours --drive weld \
        --out experiments/parity/results/strike_ours_weld_4ms.json
    python experiments/parity/slide_strike.py --side ours --drive weld --timestep 0.002 --substeps 20 \
        --out experiments/parity/results/strike_ours_weld_2ms.json
    # the reference with its arm's joint damping (or armature) scaled: how much its outcome owes to them
    experiments/parity/.venv-ref/bin/python experiments/parity/slide_strike.py --side reference \
        --episodes 1000 --arm-damping-scale 0.5 \\
        --out experiments/parity/results/strike_reference_arm_damping0p5_1000.json
    # side by side, as markdown
    python experiments/parity/slide_strike.py --summary experiments/parity/results/strike_reference.json \\
        experiments/parity/results/strike_ours.json
"""

from __future__ import annotations

import argparse
import datetime
import itertools
import json
import platform
import sys
from pathlib import Path

import mujoco
import numpy as np
from slide_strike_report import plot, response_rms, stats, summary

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path.insert(0, str(HERE))
sys.path.insert(1, str(ROOT))  # envs, for our side only: the reference's environment has no flax

DECEL = 0.1 * 9.81  # the puck-table friction's deceleration, as the controller assumes
RESPONSE_ACTIONS = [(0.16, 0.0, 0.0)] * 5 + [(0.9, 0.0, 0.0)] * 3  # close in at 8 mm / step, then jump 4.5 cm
RESPONSE_FROM_STEP = 5  # the jump
GRID_DRIVES = list(itertools.product((45.0, 50.0, 52.5, 55.0, 57.5, 60.0), (0.9, 1.0, 1.05, 1.1, 1.15, 1.2, 1.25)))
GRID_MASSES = (10.0, 16.0, 20.0)  # the default 13 kg is the default drive's row of GRID_DRIVES
# envs.fetch.models' Slide defaults, written out: this file also runs where envs cannot be imported
DEFAULT_DRIVE = {"drive_omega": 50.0, "drive_damping_ratio": 1.0}
DEFAULT_GRIPPER_MASS = 13.0
ARM_JOINTS = ("shoulder_pan", "shoulder_lift", "upperarm_roll", "elbow_flex", "forearm_roll", "wrist_flex",
              "wrist_roll")


class Recorder:
    """Collects one episode's strike from MuJoCo steps: first finger-puck contact, peak puck speed."""

    def __init__(self, m, fingers, puck, grip_site, puck_dof, direction):
        self.fingers, self.puck, self.site, self.dof = set(fingers), puck, grip_site, puck_dof
        self.u = np.asarray(direction, float)
        self.v_grip = float("nan")
        self.v_puck = 0.0
        self.strikes = 0
        self._touching = False
        self._vel = np.zeros(6)

    def __call__(self, m, d):
        touching = any(
            (c.geom1 == self.puck and c.geom2 in self.fingers) or (c.geom2 == self.puck and c.geom1 in self.fingers)
            for c in d.contact[: d.ncon]
        )
        if touching and not self._touching:
            if self.strikes == 0:
                mujoco.mj_objectVelocity(m, d, mujoco.mjtObj.mjOBJ_SITE, self.site, self._vel, 0)
                self.v_grip = float(self._vel[3:5] @ self.u)
            self.strikes += 1
        self._touching = touching
        self.v_puck = max(self.v_puck, float(d.qvel[self.dof : self.dof + 2] @ self.u))


def _launch(scripted, start_xy, goal_xy):
    v = np.asarray(scripted.launch_velocity(np.asarray(goal_xy - start_xy, np.float32)[None], DECEL))[0]
    return float(np.linalg.norm(v)), v / max(float(np.linalg.norm(v)), 1e-9)


def _landing(start_xy, goal_xy, final_xy):
    d = goal_xy - start_xy
    n = float(np.linalg.norm(d))
    disp = final_xy - start_xy
    return float(disp @ d / n - n), float(abs(disp[0] * d[1] - disp[1] * d[0]) / n)


def run_reference(episodes: int, seed: int, arm_damping_scale: float = 1.0, arm_armature_scale: float = 1.0) -> dict:
    """FetchSlide-v4 (gymnasium-robotics, MuJoCo C) with the scripted slide; its own steps, hooked.
    The scales multiply the joint damping and armature of the arm's seven joints (``ARM_JOINTS``), to
    measure how much the reference's own outcome depends on them."""
    import jax
    import run_reference as rr

    scripted = rr.load_scripted()
    policy = jax.jit(scripted.slide)
    env = rr.make_env("FetchSlide-v4")
    u_env = env.unwrapped
    m, d = u_env.model, u_env.data
    arm = [int(m.joint(f"robot0:{j}_joint").dofadr[0]) for j in ARM_JOINTS]
    m.dof_damping[arm] *= arm_damping_scale
    m.dof_armature[arm] *= arm_armature_scale
    fingers = [m.geom(f"robot0:{s}_gripper_finger_link").id for s in ("l", "r")]
    puck, site = m.geom("object0").id, m.site("robot0:grip").id
    dof = int(m.joint("object0:joint").dofadr[0])
    records = []
    for ep in range(episodes):
        obs, _ = env.reset(seed=seed + ep)
        start, goal = obs["achieved_goal"][:2].copy(), obs["desired_goal"][:2].copy()
        want, u = _launch(scripted, start, goal)
        rec = Recorder(m, fingers, puck, site, dof, u)

        def substeps(_action, rec=rec):
            for _ in range(u_env.n_substeps):
                mujoco.mj_step(m, d)
                rec(m, d)

        u_env._mujoco_step = substeps  # the env's own step, one MuJoCo step at a time
        any_success = False
        for _ in range(env.spec.max_episode_steps):
            obs, _, _, _, info = env.step(np.asarray(policy(obs["observation"], obs["desired_goal"]), float))
            any_success |= bool(info["is_success"])
        along, across = _landing(start, goal, obs["achieved_goal"][:2])
        records.append(_record(any_success, bool(info["is_success"]), want, rec, along, across))

    # Free-space response: the puck far out of reach, the same action sequence.
    env.reset(seed=seed)
    q = int(m.joint("object0:joint").qposadr[0])
    d.qpos[q : q + 2] = [1.6, 1.1]
    mujoco.mj_forward(m, d)
    speeds = []

    every = round(0.004 / m.opt.timestep)
    jac = np.zeros((3, m.nv))

    def sample(_action):  # the site's speed from the velocities after the step, as qvel gives ours
        for k in range(u_env.n_substeps):
            mujoco.mj_step(m, d)
            if (k + 1) % every == 0:
                mujoco.mj_jacSite(m, d, jac, None, site)
                speeds.append(float(jac[0] @ d.qvel))

    u_env._mujoco_step = sample
    for a in RESPONSE_ACTIONS:
        env.step(np.array([*a, 0.0]))
    import gymnasium_robotics

    side = "reference"
    if (arm_damping_scale, arm_armature_scale) != (1.0, 1.0):
        side += f", arm damping x{arm_damping_scale:g}, armature x{arm_armature_scale:g}"
    return _result(side, records, speeds, {"gymnasium_robotics": gymnasium_robotics.__version__,
                                                  "arm_damping_scale": arm_damping_scale,
                                                  "arm_armature_scale": arm_armature_scale})


def run_ours(
    episodes: int, seed: int, timestep: float = 0.004, substeps: int = 10, ep_starts=None, xml=None,
    **model_options
) -> dict:
    """Our Slide MJCF in MuJoCo C through ``slide_c.run`` (our reset, control step and controller).
    ``ep_starts`` (``slide_c.starts(episodes, seed)``) may be passed to reuse them across runs; ``xml``
    replaces the MJCF (a variant of ours with the same names, e.g. ``slide_hand.py``'s)."""
    import slide_c

    from envs.fetch import models, scripted

    xml = xml or models.mjcf("slide", timestep, 10, 4, **model_options)
    m = mujoco.MjModel.from_xml_string(xml)
    fingers = [m.geom(f"tip_{i}").id for i in range(4)]
    puck, site, dof = m.geom("object").id, m.site("grip").id, int(m.joint("object").dofadr[0])
    obj_xy, goal_xy = slide_c.starts(episodes, seed) if ep_starts is None else ep_starts
    launches = [_launch(scripted, obj_xy[i], goal_xy[i]) for i in range(episodes)]
    recs = [Recorder(m, fingers, puck, site, dof, u) for _, u in launches]
    r = slide_c.run(xml, timestep, substeps, episodes, seed, ep_starts=(obj_xy, goal_xy),
                    on_substep=lambda i, m_, d_: recs[i](m_, d_))
    records = []
    for i, (rec, (want, _)) in enumerate(zip(recs, launches, strict=True)):
        along, across = _landing(obj_xy[i], goal_xy[i], r["final"][i, :2])
        records.append(_record(bool(r["succ"][:, i].any()), bool(r["succ"][-1, i]), want, rec, along, across))

    speeds = free_response(m, substeps)
    return _result("ours", records, speeds, {"mujoco": mujoco.__version__, "model_options": model_options,
                                            "timestep": timestep, "substeps": substeps})


def free_response(m, substeps: int) -> list[float]:
    """Our grip site's x speed every 4 ms under ``RESPONSE_ACTIONS`` (``substeps`` MuJoCo steps of the
    model's timestep per control step), the puck moved out of reach."""
    from envs.fetch import models

    d = mujoco.MjData(m)
    g, q, site = int(m.joint("grip_x").qposadr[0]), int(m.joint("object").qposadr[0]), m.site("grip").id
    d.qpos[q : q + 3] = [0.6, 0.35, 0.42]
    mujoco.mj_forward(m, d)
    speeds = []
    every = round(0.004 / m.opt.timestep)
    home = np.asarray(models._SCENES["slide"][2])
    jac = np.zeros((3, m.nv))
    for a in RESPONSE_ACTIONS:
        d.ctrl[0:3] = d.qpos[g : g + 3] + 0.05 * np.asarray(a)
        if m.nmocap:  # drive="weld": the constraint pulls the gripper to the mocap target
            d.mocap_pos[0] = home + d.ctrl[0:3]
        for k in range(substeps):
            mujoco.mj_step(m, d)
            if (k + 1) % every == 0:  # the site's speed from the velocities after the step, as the reference's
                mujoco.mj_kinematics(m, d)
                mujoco.mj_jacSite(m, d, jac, None, site)
                speeds.append(float(jac[0] @ d.qvel))
    return speeds


def _record(any_success, final_success, want, rec, along, across):
    return {"success_any": any_success, "success_final": final_success, "want": want, "v_grip": rec.v_grip,
            "v_puck": rec.v_puck, "strikes": rec.strikes, "along": along, "across": across}


def _result(side, records, speeds, versions):
    per_step = 10  # 4 ms samples per 0.04 s control step
    return {
        "side": side,
        "date": datetime.date.today().isoformat(),
        "machine": f"{platform.machine()}, {platform.node()}",
        "versions": versions,
        "command": " ".join(sys.argv),
        "episodes": records,
        "response_ms": [4 * (k + 1) for k in range(3 * per_step)],
        "response_speed": speeds[RESPONSE_FROM_STEP * per_step :],
    }


def identify(runs: list[dict], reference_launch: float) -> dict:
    """The drive chosen before looking at success: among the drives whose free-space response is at least
    as close to the reference's as the default drive's, the one whose mean launch speed is closest to the
    reference's."""
    drives = [r for r in runs if "gripper_mass" not in r["options"]]
    default = next(r for r in drives if r["options"] == DEFAULT_DRIVE)
    ok = [r for r in drives if r["response_rms"] <= default["response_rms"] + 1e-12]
    return min(ok, key=lambda r: abs(r["launch_over_want"] - reference_launch))


def grid_table(grid: dict) -> str:
    out = ["| drive w (rad/s) | damping ratio | gripper kg | any (%) | final (%) | > 5 cm past (%) | > 5 cm short (%) "
           "| peak puck speed / wanted | free-space RMS vs reference (m/s) |",
           "|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in grid["runs"]:
        o = {**DEFAULT_DRIVE, "gripper_mass": DEFAULT_GRIPPER_MASS, **r["options"]}
        out.append(f"| {o['drive_omega']:g} | {o['drive_damping_ratio']:g} | {o['gripper_mass']:g} | "
                   f"{r['any']:.1f} | {r['final']:.1f} | {r['long']:.1f} | {r['short']:.1f} | "
                   f"{r['launch_over_want']:.3f} | {r.get('response_rms', float('nan')):.4f} |")
    return "\n".join(out)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--side", choices=("reference", "ours"))
    p.add_argument("--episodes", type=int, default=200)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--drive-omega", type=float, help="ours: drive natural frequency, rad/s (default 50)")
    p.add_argument("--drive-damping-ratio", type=float, help="ours: drive damping ratio (default 1)")
    p.add_argument("--gripper-mass", type=float, help="ours: gripper mass, kg (default 13)")
    p.add_argument("--drive-damping", choices=("joint", "actuator"),
                   help="ours: the drive's damping as implicit joint damping (default) or explicit actuator feedback")
    p.add_argument("--drive", choices=("pd", "weld"),
                   help="ours: the PD drive (default) or the reference's weld law, a constraint to a mocap target")
    p.add_argument("--arm-damping-scale", type=float, default=1.0,
                   help="reference: multiply the arm joints' damping by this (default 1: as shipped)")
    p.add_argument("--arm-armature-scale", type=float, default=1.0,
                   help="reference: multiply the arm joints' armature by this (default 1: as shipped)")
    p.add_argument("--timestep", type=float, default=0.004, help="ours: MuJoCo timestep, s (the reference: 0.002)")
    p.add_argument("--substeps", type=int, default=10, help="ours: MuJoCo steps per 0.04 s control step")
    p.add_argument("--grid", action="store_true", help="ours: every drive in GRID_DRIVES, then every GRID_MASSES")
    p.add_argument("--reference-json", help="with --grid: a --side reference run, to score each drive against")
    p.add_argument("--out", help="JSON file for the run")
    p.add_argument("--summary", nargs="+", metavar="JSON", help="print a markdown table of these runs and exit")
    p.add_argument("--grid-json", help="with --summary: a --grid run to tabulate and plot")
    p.add_argument("--png", help="with --summary: draw the figure here")
    args = p.parse_args(argv)
    if args.summary:
        results = [json.loads(Path(f).read_text()) for f in args.summary]
        grid = json.loads(Path(args.grid_json).read_text()) if args.grid_json else None
        print(summary(results))
        if grid:
            print("\n" + grid_table(grid))
        if args.png:
            plot(results, grid, args.png)
            print("wrote", args.png)
        return 0
    if args.side is None:
        p.error("--side is required unless --summary is given")
    if args.side == "ours" and (args.arm_damping_scale != 1.0 or args.arm_armature_scale != 1.0):
        p.error("--arm-damping-scale and --arm-armature-scale are for --side reference")
    if not (args.arm_damping_scale >= 0 and args.arm_armature_scale >= 0):
        p.error("--arm-damping-scale and --arm-armature-scale must be >= 0")
    if args.side == "reference":
        if (args.grid or args.drive_omega or args.drive_damping_ratio or args.gripper_mass or args.drive_damping
                or args.drive):
            p.error("--grid and the model options are for --side ours")
        result = run_reference(args.episodes, args.seed, args.arm_damping_scale, args.arm_armature_scale)
    elif args.grid:
        runs = [dict(drive_omega=w, drive_damping_ratio=z) for w, z in GRID_DRIVES]
        runs += [dict(gripper_mass=mass) for mass in GRID_MASSES]
        result = {"side": "ours grid", "date": datetime.date.today().isoformat(), "command": " ".join(sys.argv),
                  "runs": []}
        ref = json.loads(Path(args.reference_json).read_text()) if args.reference_json else None
        import slide_c

        starts = slide_c.starts(args.episodes, args.seed)
        for options in runs:
            run = run_ours(args.episodes, args.seed, ep_starts=starts, **options)
            s = stats(run)
            row = {"options": options, **{k: s[k] for k in ("any", "final", "long", "short")},
                   "launch_over_want": s["launch_over_want"][0]}
            if ref:
                row["response_rms"] = response_rms(run, ref)
            result["runs"].append(row)
            print(options, {k: round(v, 4) for k, v in row.items() if k != "options"}, flush=True)
        if ref:
            result["identified"] = identify(result["runs"], stats(ref)["launch_over_want"][0])
            print("identified drive:", result["identified"])
    else:
        opts = {k: v for k, v in (("drive_omega", args.drive_omega), ("drive_damping_ratio", args.drive_damping_ratio),
                                  ("gripper_mass", args.gripper_mass), ("drive_damping", args.drive_damping),
                                  ("drive", args.drive))
                if v is not None}
        if abs(args.timestep * args.substeps - 0.04) > 1e-9:
            p.error(f"--timestep x --substeps must be the 0.04 s control step, got {args.timestep * args.substeps:g}")
        result = run_ours(args.episodes, args.seed, args.timestep, args.substeps, **opts)
    if "episodes" in result and isinstance(result["episodes"], list):
        print(summary([result]))
    if args.out:
        Path(args.out).write_text(json.dumps(result, indent=1) + "\n")
        print("wrote", args.out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
