"""Slide's strike with a hand that turns: is the reference arm's inertia at the hand what our gripper lacks?

Our Slide gripper is one rigid body on three slide joints. The reference's hangs on a 7-joint arm held
by a 6-row mocap weld, so a push along x also turns the hand about y (and a push along y turns it
about x). This builds a reduced-order stand-in for that arm and runs Slide's strike with it:

1. ``--measure`` (in the reference's environment): at the FetchSlide-v4 start, with the base and torso
   held, the arm's operational-space inertia Lambda = (J M^-1 J^T)^-1 at the grip site and its joints'
   damping seen there, C = Lambda J M^-1 D M^-1 J^T Lambda; the (x, ry), (y, rx) and z blocks.
2. ``fit``: a chain of our own (slides x; y and z; a hinge about y; a hinge about x carrying the fingers)
   whose Lambda and C in those blocks equal the measured ones. Each hinge sits where the measured damping
   decouples (so joint damping, which is diagonal, reproduces it); the masses, centres of mass and
   inertias then follow from Lambda, with the hand's mass (``HAND_MASS``) chosen.
3. ``--side ours`` runs the strike (``slide_strike.run_ours``, MuJoCo C) with that hand, held to the
   mocap target by a weld with the reference's solref / solimp, at ``--damping-scale`` times the fitted
   joint damping. ``--response`` scores damping scales by the free-space response alone, before any
   strike is run.

    experiments/parity/.venv-ref/bin/python experiments/parity/slide_hand.py --measure \\
        --out experiments/parity/results/hand_opspace_reference.json
    python experiments/parity/slide_hand.py --response experiments/parity/results/hand_opspace_reference.json \\
        --reference-json experiments/parity/results/strike_reference.json --timestep 0.002
    python experiments/parity/slide_hand.py --side ours --fit experiments/parity/results/hand_opspace_reference.json \\
        --damping-scale 0 --out experiments/parity/results/strike_ours_hand_damping0_4ms.json
"""

from __future__ import annotations

import argparse
import json
import re
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(1, str(HERE.parents[1]))

from slide_strike import ARM_JOINTS  # noqa: E402

HAND_MASS = 10.0  # kg below the x hinge (fingers and palm); must exceed Lambda's bound, see fit()
RY_BODY_MASS = 1.0  # kg between the y and x hinges
RY_BODY_INERTIA = 0.01  # kg m^2


def _opspace(mass, jac, damping) -> tuple[np.ndarray, np.ndarray]:
    """Lambda = (J M^-1 J^T)^-1 and the joint damping seen through J, C = Lambda J M^-1 D M^-1 J^T Lambda
    (dynamically consistent: the joint rates of the least-inertia motion)."""
    lam = np.linalg.inv(jac @ np.linalg.solve(mass, jac.T))
    proj = lam @ jac @ np.linalg.inv(mass)
    return lam, proj @ np.diag(damping) @ proj.T


def measure() -> dict:
    """Lambda and C at the reference's grip site, FetchSlide-v4 reset with seed 0, base and torso held."""
    import gymnasium as gym
    import gymnasium_robotics
    import mujoco

    gym.register_envs(gymnasium_robotics)
    env = gym.make("FetchSlide-v4").unwrapped
    env.reset(seed=0)
    m, d = env.model, env.data
    mujoco.mj_forward(m, d)
    arm = [int(m.joint(f"robot0:{j}_joint").dofadr[0]) for j in ARM_JOINTS]
    full = np.zeros((m.nv, m.nv))
    mujoco.mj_fullM(m, d, full)
    mass = full[np.ix_(arm, arm)]
    jp, jr = np.zeros((3, m.nv)), np.zeros((3, m.nv))
    mujoco.mj_jacSite(m, d, jp, jr, m.site("robot0:grip").id)
    lam, damp = _opspace(mass, np.vstack([jp, jr])[:, arm], m.dof_damping[arm])
    return {"env": "FetchSlide-v4", "seed": 0, "gymnasium_robotics": gymnasium_robotics.__version__,
            "mujoco": mujoco.__version__, "rows": ["x", "y", "z", "rx", "ry", "rz"],
            "lambda": lam.tolist(), "damping": damp.tolist()}


def fit(measured: dict) -> dict:
    """Our chain's parameters from the measured blocks (site frame: heights above the grip site)."""
    lam, c = np.asarray(measured["lambda"]), np.asarray(measured["damping"])
    x, y, z, rx, ry = 0, 1, 2, 3, 4
    # (x, ry): v_x = xdot + r theta_y with r the site's height relative to the y hinge (below it: r < 0).
    r = -c[x, ry] / c[x, x]
    jac = np.array([[1.0, r], [0.0, 1.0]])
    mxr = jac.T @ lam[np.ix_([x, ry], [x, ry])] @ jac
    dxr = jac.T @ c[np.ix_([x, ry], [x, ry])] @ jac
    pivot_y = -r
    # (y, rx): v_y = ydot - s theta_x with s the site's height relative to the x hinge.
    s = c[y, rx] / c[y, y]
    jac = np.array([[1.0, -s], [0.0, 1.0]])
    myr = jac.T @ lam[np.ix_([y, rx], [y, rx])] @ jac
    dyr = jac.T @ c[np.ix_([y, rx], [y, rx])] @ jac
    pivot_x = -s
    m2 = HAND_MASS
    if m2 < myr[0, 1] ** 2 / myr[1, 1]:
        raise ValueError(f"HAND_MASS {m2} below the bound {myr[0, 1] ** 2 / myr[1, 1]:.2f} kg")
    z2 = pivot_x - myr[0, 1] / m2  # the hand's centre of mass (y_com = y - (z2 - pivot_x) theta_x)
    i2x = myr[1, 1] - myr[0, 1] ** 2 / m2
    m1 = RY_BODY_MASS
    z1 = pivot_y + (mxr[0, 1] - m2 * (z2 - pivot_y)) / m1
    i2y = mxr[1, 1] - m1 * (z1 - pivot_y) ** 2 - m2 * (z2 - pivot_y) ** 2 - RY_BODY_INERTIA
    y_carrier = lam[y, y] - m1 - m2
    x_carrier = lam[x, x] - lam[y, y]
    out = {"pivot_y": pivot_y, "pivot_x": pivot_x, "hand_mass": m2, "hand_com": z2, "hand_inertia_x": i2x,
           "hand_inertia_y": i2y, "ry_mass": m1, "ry_com": z1, "ry_inertia": RY_BODY_INERTIA,
           "y_carrier_mass": y_carrier, "x_carrier_mass": x_carrier,
           "damping_x": dxr[0, 0], "damping_ry": dxr[1, 1], "damping_y": dyr[0, 0], "damping_rx": dyr[1, 1],
           "damping_z": c[z, z], "offdiag_left": max(abs(dxr[0, 1]), abs(dyr[0, 1]))}
    bad = [k for k in ("hand_inertia_x", "hand_inertia_y", "y_carrier_mass", "x_carrier_mass") if out[k] <= 0]
    if bad:
        raise ValueError(f"no such chain: {bad} not positive ({ {k: out[k] for k in bad} })")
    return out


def hand_mjcf(p: dict, timestep: float, damping_scale: float = 1.0, options: dict | None = None) -> str:
    """Our Slide MJCF (weld law) with the gripper body replaced by the fitted chain; names kept.
    ``options``: ``models.mjcf``'s keywords of another Slide variant (e.g. a task's ``model_options()``;
    ``drive`` must be "weld"), its timestep replaced by ``timestep``."""
    from envs.fetch import models

    opts = {"iterations": 10, "ls_iterations": 4, **(options or {}), "timestep": timestep, "drive": "weld"}
    base = models.mjcf("slide", **opts)
    body = re.search(r'    <body name="gripper".*?\n    </body>', base, re.S).group(0)
    inner = body.split("\n", 4)[4].rsplit("\n", 1)[0]  # the site, palm, finger block and tips
    inner = re.sub(r'(<geom name="palm"[^>]*?)mass="[^"]*"', r'\1mass="0.001"', inner, flags=re.S)
    inner = "\n".join("      " + line for line in inner.split("\n"))
    k = damping_scale
    iz = min(p["hand_inertia_x"], p["hand_inertia_y"])
    ry_i = p["ry_inertia"]
    home = models._fmt(*models._SCENES["slide"][2])
    chain = f"""    <body name="carrier_x" pos="{home}">
      <joint name="grip_x" type="slide" axis="1 0 0" damping="{k * p['damping_x']:.6g}"/>
      <inertial pos="0 0 0.3" mass="{p['x_carrier_mass']:.6g}" diaginertia="0.1 0.1 0.1"/>
      <body name="gripper">
        <joint name="grip_y" type="slide" axis="0 1 0" damping="{k * p['damping_y']:.6g}"/>
        <joint name="grip_z" type="slide" axis="0 0 1" damping="{k * p['damping_z']:.6g}"/>
        <inertial pos="0 0 0.3" mass="{p['y_carrier_mass']:.6g}" diaginertia="0.1 0.1 0.1"/>
        <body name="hand_ry">
          <joint name="hand_ry" type="hinge" axis="0 1 0" pos="0 0 {p['pivot_y']:.6g}"
                 damping="{k * p['damping_ry']:.6g}"/>
          <inertial pos="0 0 {p['ry_com']:.6g}" mass="{p['ry_mass']:.6g}" diaginertia="{ry_i} {ry_i} {ry_i}"/>
          <body name="hand">
            <joint name="hand_rx" type="hinge" axis="1 0 0" pos="0 0 {p['pivot_x']:.6g}"
                   damping="{k * p['damping_rx']:.6g}"/>
            <inertial pos="0 0 {p['hand_com']:.6g}" mass="{p['hand_mass']:.6g}"
                      diaginertia="{p['hand_inertia_x']:.6g} {p['hand_inertia_y']:.6g} {iz:.6g}"/>
{inner}
          </body>
        </body>
      </body>
    </body>"""
    out = base.replace(body, chain)
    out = out.replace('<connect body1="gripper" body2="target" anchor="0 0 0"',
                      '<weld body1="target" body2="hand" anchor="0 0 0"')
    z_mass = p["y_carrier_mass"] + p["ry_mass"] + p["hand_mass"]  # what the z slide lifts
    return re.sub(r'(<general name="grip_z"[^>]*?biasprm=")[^ ]+', rf"\g<1>{z_mass * 9.81:.6g}", out, flags=re.S)


def opspace(xml: str) -> tuple[np.ndarray, np.ndarray]:
    """Lambda and C of our chain at the grip site over (x, y, z, rx, ry): the check on ``fit``."""
    import mujoco

    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    dofs = [int(m.joint(n).dofadr[0]) for n in ("grip_x", "grip_y", "grip_z", "hand_rx", "hand_ry")]
    full = np.zeros((m.nv, m.nv))
    mujoco.mj_fullM(m, d, full)
    mass = full[np.ix_(dofs, dofs)]
    jp, jr = np.zeros((3, m.nv)), np.zeros((3, m.nv))
    mujoco.mj_jacSite(m, d, jp, jr, m.site("grip").id)
    return _opspace(mass, np.vstack([jp, jr])[:5][:, dofs], m.dof_damping[dofs])


def fit_error(measured: dict, params: dict) -> float:
    """Largest relative difference between the chain of ``params`` (``fit(measured)``; damping scale 1)
    and the measured (x, ry) and (y, rx) blocks of Lambda and C."""
    lam, c = np.asarray(measured["lambda"]), np.asarray(measured["damping"])
    ours_lam, ours_c = opspace(hand_mjcf(params, 0.004, 1.0))
    err = 0.0
    for idx in ([0, 4], [1, 3]):
        for a, b in ((ours_lam, lam), (ours_c, c)):
            block, want = a[np.ix_(idx, idx)], b[np.ix_(idx, idx)]
            err = max(err, float(np.max(np.abs(block - want)) / np.max(np.abs(want))))
    return err


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--measure", action="store_true", help="reference side: measure Lambda and C")
    p.add_argument("--side", choices=("ours",), help="run the strike with the fitted hand")
    p.add_argument("--fit", help="JSON from --measure")
    p.add_argument("--response", help="JSON from --measure: score damping scales by the free-space response")
    p.add_argument("--reference-json", help="with --response: a slide_strike.py --side reference run")
    p.add_argument("--damping-scale", type=float, default=1.0, help="times the fitted joint damping (>= 0)")
    p.add_argument("--timestep", type=float, default=0.004, help="MuJoCo timestep, s (0.04 s control step)")
    p.add_argument("--episodes", type=int, default=200)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--out")
    args = p.parse_args(argv)
    if args.damping_scale < 0:
        p.error(f"--damping-scale must be >= 0, got {args.damping_scale}")
    substeps = round(0.04 / args.timestep)
    if abs(substeps * args.timestep - 0.04) > 1e-9:
        p.error(f"--timestep must divide the 0.04 s control step, got {args.timestep}")
    if args.measure:
        result = measure()
        print(json.dumps(result, indent=1))
    elif args.response:
        import mujoco
        import slide_strike as ss

        if not args.reference_json:
            p.error("--response needs --reference-json")
        params = fit(json.loads(Path(args.response).read_text()))
        ref = json.loads(Path(args.reference_json).read_text())
        result = {"timestep": args.timestep, "scores": []}
        for scale in (0.0, 0.1, 0.2, 0.3, 0.5, 0.75, 1.0):
            m = mujoco.MjModel.from_xml_string(hand_mjcf(params, args.timestep, scale))
            speeds = ss.free_response(m, substeps)
            rms = ss.response_rms({"response_speed": speeds[ss.RESPONSE_FROM_STEP * 10 :]}, ref)
            result["scores"].append({"damping_scale": scale, "response_rms": rms})
            print(f"damping x{scale:g}: free-space response RMS from the reference {rms:.4f} m/s", flush=True)
        result["chosen"] = min(result["scores"], key=lambda r: r["response_rms"])
        print("closest:", result["chosen"])
    elif args.side == "ours":
        import slide_strike as ss

        if not args.fit:
            p.error("--side ours needs --fit")
        measured = json.loads(Path(args.fit).read_text())
        params = fit(measured)
        xml = hand_mjcf(params, args.timestep, args.damping_scale)
        print(f"fitted blocks (x, ry), (y, rx): largest relative error {fit_error(measured, params):.2e}")
        result = ss.run_ours(args.episodes, args.seed, args.timestep, substeps, xml=xml)
        result["side"] = f"ours, turning hand, damping x{args.damping_scale:g}, {args.timestep * 1000:g} ms"
        result["versions"]["hand"] = params
        result["versions"]["damping_scale"] = args.damping_scale
        result["command"] = " ".join(sys.argv)
        print(ss.summary([result]))
    else:
        p.error("one of --measure, --response, --side ours")
    if args.out:
        Path(args.out).write_text(json.dumps(result, indent=1) + "\n")
        print("wrote", args.out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
