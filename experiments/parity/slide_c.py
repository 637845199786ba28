"""Fast Slide experiments in MuJoCo C: our Slide MJCF (or a variant of it), our reset and control
step, and the ``envs.fetch.scripted.slide`` controller, all episodes in lock step.

The MJX task takes about a minute to compile on a 2-core CPU; this replica runs 200 episodes in
seconds, so model variants are screened here and then confirmed in MJX with ``run_ours.py``:

    /work/venv/bin/python experiments/parity/slide_c.py --episodes 200
    /work/venv/bin/python experiments/parity/slide_c.py --xml variant.xml --timestep 0.002 --substeps 20

Per variant it prints any-step / final-step success and what goes wrong in the failures: the puck
tipped (roll or pitch past 0.2 rad), left the table top height, ended off the aimed line, short or
long of the goal (each by more than 5 cm along or across the line).
"""

from __future__ import annotations

import argparse
import contextlib
import io
import sys
from pathlib import Path

import mujoco
import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))


def starts(episodes: int, seed: int = 0):
    """Object xy and goal xy of ``run_ours.py``'s episodes (same keys), from the MJX task's reset."""
    import jax

    import envs

    with contextlib.redirect_stdout(io.StringIO()):
        env = envs.make("slide")
        s0 = jax.jit(lambda k: jax.vmap(env.reset)(jax.random.split(k, episodes)))(jax.random.PRNGKey(seed))
    return np.asarray(s0.achieved_goal[:, :2], float), np.asarray(s0.desired_goal[:, :2], float)


def run(
    xml: str,
    timestep: float,
    substeps: int,
    episodes: int = 200,
    seed: int = 0,
    controller=None,
    steps: int = 50,
    ep_starts=None,
    on_substep=None,
    workspace="arm",
    drift=0.0,
):
    """Run the slide controller on ``xml``; returns a dict of per-episode arrays. ``on_substep(i, m, d)``,
    if given, is called after every MuJoCo step of episode ``i``. ``workspace`` is the task field's:
    "arm" also keeps the gripper target within the reference arm's reach, "box" does not. ``drift`` is the task field
    ``arm_drift`` (Slide's default 1.5; the results recorded here ran without it)."""
    import jax

    from envs.fetch import control, models, scripted

    m = mujoco.MjModel.from_xml_string(xml)
    m.opt.timestep = timestep
    g = int(m.joint("grip_x").qposadr[0])
    o = int(m.joint("object").qposadr[0])
    ov = int(m.joint("object").dofadr[0])
    site = m.site("grip").id
    jac = np.zeros((3, m.nv))
    home = np.asarray(models._SCENES["slide"][2])
    lo, hi = models.workspace_box("slide")
    rest_z = models.rest_height(m, o)
    reach_center = control.ARM_REACH_CENTER["slide"] if workspace == "arm" else None
    obj_xy, goal_xy = starts(episodes, seed) if ep_starts is None else ep_starts
    goal = np.concatenate([goal_xy, np.full((episodes, 1), rest_z)], axis=1)
    ds = []
    for i in range(episodes):
        d = mujoco.MjData(m)
        d.qpos[o : o + 7] = [*obj_xy[i], rest_z, 1, 0, 0, 0]
        mujoco.mj_forward(m, d)
        ds.append(d)
    ctl = jax.jit(controller or scripted.slide)
    dt = timestep * substeps
    succ = np.zeros((steps, episodes), bool)
    tilt = np.zeros(episodes)
    zmax = np.zeros(episodes)
    wz = np.zeros(episodes)
    bad = np.zeros(episodes, bool)
    start = np.array([d.qpos[o : o + 3].copy() for d in ds])
    traj = np.zeros((steps + 1, episodes, 25), np.float32)
    for t in range(steps + 1):
        obs = np.zeros((episodes, 25), np.float32)
        for i, d in enumerate(ds):
            mujoco.mj_kinematics(m, d)  # the grip site where the step left it (a hinged hand may turn)
            mujoco.mj_jacSite(m, d, jac, None, site)
            grip = d.site_xpos[site].copy()
            obj = d.qpos[o : o + 3]
            gv = (jac @ d.qvel) * dt
            obs[i, 0:3], obs[i, 3:6], obs[i, 6:9] = grip, obj, obj - grip
            obs[i, 14:17] = d.qvel[ov : ov + 3] * dt - gv
            obs[i, 20:23] = gv
        traj[t] = obs
        if t == steps:
            break
        act = np.clip(np.asarray(ctl(obs, goal.astype(np.float32)), float), -1, 1)
        for i, d in enumerate(ds):
            if bad[i]:
                continue
            d.ctrl[0:3] = control.gripper_target(d.qpos[g : g + 3], act[i, :3], home, lo, hi, reach_center, drift=drift)
            if m.nmocap:  # drive="weld": the constraint pulls the gripper to the mocap target
                d.mocap_pos[0] = home + d.ctrl[0:3]
            for _ in range(substeps):
                mujoco.mj_step(m, d)
                if on_substep is not None:
                    on_substep(i, m, d)
            if not np.isfinite(d.qpos).all() or d.warning[mujoco.mjtWarning.mjWARN_BADQACC].number:
                bad[i] = True
                continue
            q = d.qpos[o + 3 : o + 7]
            up = np.array(
                [2 * (q[1] * q[3] + q[0] * q[2]), 2 * (q[2] * q[3] - q[0] * q[1]), 1 - 2 * (q[1] ** 2 + q[2] ** 2)]
            )
            tilt[i] = max(tilt[i], np.arccos(np.clip(up[2], -1, 1)))
            zmax[i] = max(zmax[i], d.qpos[o + 2] - rest_z)
            wz[i] = max(wz[i], abs(d.qvel[ov + 5]))
            succ[t, i] = np.linalg.norm(d.qpos[o : o + 3] - goal[i]) < 0.05
    final = np.array([d.qpos[o : o + 3].copy() for d in ds])
    return {
        "succ": succ,
        "tilt": tilt,
        "zmax": zmax,
        "wz": wz,
        "bad": bad,
        "start": start,
        "final": final,
        "goal": goal,
        "obs": traj,
    }


def summary(r) -> str:
    succ = r["succ"]
    d = r["goal"][:, :2] - r["start"][:, :2]
    u = d / np.linalg.norm(d, axis=1, keepdims=True)
    disp = r["final"][:, :2] - r["start"][:, :2]
    along = np.sum(disp * u, 1) - np.linalg.norm(d, axis=1)
    across = np.abs(disp[:, 0] * u[:, 1] - disp[:, 1] * u[:, 0])
    return (
        f"any {100 * succ.any(0).mean():5.1f} final {100 * succ[-1].mean():5.1f} | "
        f"tipped {np.mean(r['tilt'] > 0.2) * 100:4.1f}% lifted>1cm {np.mean(r['zmax'] > 0.01) * 100:4.1f}% "
        f"yaw-rate median {np.median(r['wz']):.2f} p90 {np.percentile(r['wz'], 90):.2f} rad/s | "
        f"off-line {np.mean(across > 0.05) * 100:4.1f}% short {np.mean(along < -0.05) * 100:4.1f}% "
        f"long {np.mean(along > 0.05) * 100:4.1f}% | unstable {int(r['bad'].sum())}"
    )


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--xml", help="MJCF file of a Slide variant (default: envs.fetch.models.mjcf('slide'))")
    p.add_argument("--timestep", type=float, default=0.004)
    p.add_argument("--substeps", type=int, default=10)
    p.add_argument("--iterations", type=int, default=10)
    p.add_argument("--ls-iterations", type=int, default=4)
    p.add_argument("--episodes", type=int, default=200)
    p.add_argument("--seed", type=int, default=0)
    args = p.parse_args(argv)
    from envs.fetch import models

    xml = (
        Path(args.xml).read_text()
        if args.xml
        else models.mjcf("slide", args.timestep, args.iterations, args.ls_iterations)
    )
    print(summary(run(xml, args.timestep, args.substeps, args.episodes, args.seed)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
