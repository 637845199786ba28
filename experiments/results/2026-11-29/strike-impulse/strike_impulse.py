"""Slide's scripted strike (``envs.fetch.scripted.slide``) from the same starts in our task (MJX) and in
FetchSlide-v4 (MuJoCo C), traced at every physics step: when the pads touch the puck, how fast it leaves them and
how far it slides after the last touch.

    # ours: draws the starts (the evaluator's: ``mapping.our_starts``) and writes them beside its result
    PYTHONPATH=. python strike_impulse.py ours --episodes 100 --starts S.npz --out OURS.json \
        --env-options finger=pads,finger_table=1,drive=weld,gripper_mass=22 [--pair solref="0.01 1"] ...
    # the reference, from those starts (a venv with mujoco 3.11.0 and gymnasium-robotics 1.4.2)
    PYTHONPATH=. REF/bin/python strike_impulse.py reference --starts S.npz --out REF.json
    python strike_impulse.py summarise REF.json OURS.json ...   # .json or .json.gz
    python strike_impulse.py trim FILE.json.gz ...   # per-step traces replaced by their sudden-slowing counts

``--pair ATTR=VALUE`` rewrites one attribute of the pad-puck pair (``slide_fingers.PAD_PUCK_CONTACT``) before the
model is built; ``--puck-friction`` the puck's sliding friction on the table (``models``' Slide friction string);
``--weld-solref`` the weld drive's (``models.WELD_SOLREF``); ``--armature`` adds inertia along the gripper's slide
joints (x, y, z); ``--pads-symmetric`` centres the two pads about the grip site, ``--pad-xy X,Y`` puts them at
(X, +-Y). Ours needs ``finger=pads``. ``--aim-short F`` (both sides) aims the strike to stop F of the way short,
launching it slower.

A touch: a pad within the pair's margin (1 mm) of the puck (ours: ``envs/box_cylinder.py`` on the step's poses;
the reference: a finger-puck contact in MuJoCo's list). Per episode: the grip's speed along the launch line at the
first touch, the puck's speed as the first touch ends (``v_first``) and as the last ends (``v_last``), its peak
after the first touch, the touches begun, the seconds in contact, the distance slid after the last touch, success.
"""

from __future__ import annotations

import argparse
import gzip
import importlib.util
import json
import os
import re
import sys

import numpy as np

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), *[".."] * 4)
sys.path.insert(0, ROOT)
DECEL = 0.1 * 9.81
KEYS = ("along", "across", "dir_first", "v_grip", "v_first", "v_last", "v_peak", "v_grip_after", "v_before_last",
        "touches", "contact_s", "first_contact_s", "tilt_max", "z_min", "t_first_end", "t_last_end", "slid",
        "success_any", "success_final")  # fmt: skip


def scripted():
    spec = importlib.util.spec_from_file_location("scripted", os.path.join(ROOT, "envs", "fetch", "scripted.py"))
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def episode_stats(t, touch, pxy, pvel, gvel, u, success, final_ok, start, goal, per_control=1, pose=None):
    """One episode's numbers from its physics-step trace: times ``t`` [S], touch flags [S], puck xy [S, 2],
    puck velocity xy [S, 2], grip velocity xy [S, 2], the launch direction ``u`` (xy, unit)."""
    touch = np.asarray(touch, bool)
    speed = np.linalg.norm(pvel, axis=1)
    rec = {k: float("nan") for k in KEYS}
    d = goal - start
    n = float(np.linalg.norm(d))
    disp = pxy[-1] - start
    rec["tilt_max"], rec["z_min"] = float("nan"), float("nan")
    rec["along"] = float(disp @ d / n - n)  # where it ends: past the goal > 0
    rec["across"] = float(abs(disp[0] * d[1] - disp[1] * d[0]) / n)
    rec["speed_per_step"] = np.round(speed[per_control - 1 :: per_control], 3).tolist()  # at each control step's end
    rec["touch_per_step"] = touch.reshape(-1, per_control).any(axis=1).astype(int).tolist()
    if pose is not None:  # the puck's centre height and tilt (degrees) at each control step's end
        x, y = pose[:, 2], pose[:, 3]
        tilt = np.degrees(np.arccos(np.clip(1 - 2 * (x * x + y * y), -1, 1)))
        z = pose[:, 0] - pose[0, 0]  # from where it rests at the start
        rec["tilt_max"] = float(tilt.max())
        rec["z_min"] = float(z.min())
    rec.update(touches=0, contact_s=0.0, first_contact_s=0.0, slid=0.0, success_any=bool(success),
               success_final=bool(final_ok))  # fmt: skip
    if not touch.any():
        return rec
    dt = float(t[1] - t[0])
    starts = np.flatnonzero(touch & ~np.r_[False, touch[:-1]])
    ends = np.flatnonzero(touch & ~np.r_[touch[1:], False])  # last touching step of each touch
    first, last = starts[0], ends[-1]
    after = lambda i: min(i + 1, len(t) - 1)  # noqa: E731
    rec.update(
        v_grip=float(gvel[first] @ u),
        v_first=float(speed[after(ends[0])]),
        dir_first=float(
            np.degrees(
                np.arctan2(u[0] * pvel[after(ends[0])][1] - u[1] * pvel[after(ends[0])][0], u @ pvel[after(ends[0])])
            )
        ),
        v_last=float(speed[after(last)]),
        v_peak=float(speed[first:].max()),
        v_grip_after=float(gvel[after(ends[0])] @ u),
        v_before_last=float(speed[max(starts[-1] - 1, 0)]),
        t_first_end=float(t[ends[0]]),
        t_last_end=float(t[last]),
        touches=int(len(starts)),
        contact_s=float(touch.sum() * dt),
        first_contact_s=float((ends[0] - starts[0] + 1) * dt),
        slid=float(np.linalg.norm(pxy[-1] - pxy[last])),
    )
    return rec


# ---------------------------------------------------------------- ours (MJX)


def patch_pair(
    pairs: list[str],
    puck_friction: float | None,
    weld_solref: str | None = None,
    armature: list[float] | None = None,
    pads_symmetric: bool = False,
    pad_xy: tuple[float, float] | None = None,
) -> None:
    """Our model's changes for the sweep, made before ``envs.make`` builds it (no task option holds them)."""
    from envs.fetch import models, slide_fingers

    s = slide_fingers.PAD_PUCK_CONTACT
    for p in pairs:
        key, value = p.split("=", 1)
        s, n = re.subn(rf'{key}="[^"]*"', f'{key}="{value.strip(chr(34))}"', s)
        if not n:
            s += f' {key}="{value.strip(chr(34))}"'
    slide_fingers.PAD_PUCK_CONTACT = s
    if weld_solref:
        models.WELD_SOLREF = weld_solref
    if pads_symmetric:  # the two pads' centres mirrored about the grip site (the reference's are 1.5 mm off)
        (xr, yr, zr), (xl, yl, zl) = slide_fingers.PAD_CENTERS
        half = (yr - yl) / 2
        slide_fingers.PAD_CENTERS = ((xr, half, zr), (xl, -half, zl))
    if pad_xy:  # the pads at x, +-y about the grip site (FetchSlide-v4's at the strike: -0.0002, 0.008)
        (_, _, zr), (_, _, zl) = slide_fingers.PAD_CENTERS
        slide_fingers.PAD_CENTERS = ((pad_xy[0], pad_xy[1], zr), (pad_xy[0], -pad_xy[1], zl))
    edits = []
    if puck_friction is not None:
        edits.append(('friction="0.1 0.1 0.005 0.0001 0.0001"',
                      f'friction="{puck_friction} {puck_friction} 0.005 0.0001 0.0001"'))  # fmt: skip
    for axis, value in zip("xyz", armature or (), strict=False):
        edits.append((f'<joint name="grip_{axis}" type="slide" axis=', f'<joint name="grip_{axis}" armature="{value}" '
                      'type="slide" axis='))  # fmt: skip
    if edits:
        old = models.mjcf

        def mjcf(*a, **k):
            text = old(*a, **k)
            for before, after in edits:
                assert before in text, before
                text = text.replace(before, after)
            return text

        models.mjcf = mjcf


SLIDE = {}  # keyword arguments of the scripted strike (``--aim-short``)


def run_ours(options: dict, episodes: int, seed: int) -> tuple[dict, dict]:
    import dataclasses

    import jax
    import jax.numpy as jnp
    from mujoco import mjx

    import envs
    from envs.base import make_data
    from envs.box_cylinder import box_cylinder
    from envs.fetch import models
    from splid_jax.reference.mapping import our_starts

    sc = scripted()
    env = envs.make("slide", **options)
    one = dataclasses.replace(env, substeps=1)
    m = env.mj_model
    gid = lambda n: m.geom(n).id  # noqa: E731
    puck, pads = gid("object"), [gid("pad_r"), gid("pad_l")]
    margin = float(m.pair_margin.max()) if m.npair else 0.001
    model = env.mjx_model
    o = env.layout.object_q
    site = m.site("grip").id if "grip" in [m.site(i).name for i in range(m.nsite)] else 0

    def poses(phys):
        with models.own_contacts(m):  # make_data asks for the pad-puck collision MJX lacks
            d = mjx.kinematics(model, make_data(model).replace(qpos=phys.qpos, qvel=phys.qvel))
        dist = jnp.min(jnp.stack([
            jnp.min(box_cylinder(d.geom_xpos[puck], d.geom_xmat[puck], jnp.asarray(m.geom_size[puck][:2]),
                                 d.geom_xpos[p], d.geom_xmat[p], jnp.asarray(m.geom_size[p]))[0])
            for p in pads]))  # fmt: skip
        return dist, d.site_xpos[site][:2]

    def one_episode(s0):
        def control_step(s, _):
            act = sc.slide(s.obs, s.desired_goal, **SLIDE)
            ctrl = env._control(s.physics, env._action(act))

            def sub(phys, _):
                nxt = one.simulate(phys, ctrl)
                dist, grip = poses(nxt)
                return nxt, (dist, nxt.qpos[o : o + 2], nxt.qvel[o : o + 2], grip, nxt.qpos[o + 2 : o + 7])

            phys, rows = jax.lax.scan(sub, s.physics, None, length=env.substeps)
            nxt = env._state(phys, s.desired_goal, s.step + 1, s.invalid)
            return nxt, (rows, nxt.success)

        last, (rows, succ) = jax.lax.scan(control_step, s0, None, length=env.episode_length)
        return rows, succ

    starts = our_starts(env, jax.random.PRNGKey(seed), episodes)
    rows, succ = jax.jit(jax.vmap(one_episode))(starts["state"])
    dist, pxy, pvel, grip, pose = (np.asarray(x, np.float64).reshape(episodes, -1, *x.shape[3:]) for x in rows)
    succ = np.asarray(succ)
    dt = env.timestep
    t = np.arange(dist.shape[1]) * dt + dt
    gvel = np.gradient(grip, dt, axis=1)
    out = []
    for i in range(episodes):
        start, goal = starts["object_xy"][i], starts["goal"][i][:2]
        u = np.asarray(sc.launch_velocity(np.asarray(goal - start, np.float32)[None], DECEL))[0]
        u = u / max(np.linalg.norm(u), 1e-9)
        out.append(episode_stats(t, dist[i] < margin, pxy[i], pvel[i], gvel[i], u, succ[i].any(), succ[i][-1], start,
                                 goal, env.substeps, pose[i]))  # fmt: skip
    saved = {
        "object_xy": starts["object_xy"],
        "goal": starts["goal"],
        "grip_home": np.asarray(env.layout.grip_home),
        "object_rest_z": np.float64(env.layout.object_rest_z),
    }
    return {"pair": slide_fingers_contact(), "timestep": dt, "episodes": out}, saved


def slide_fingers_contact() -> str:
    from envs.fetch import slide_fingers

    return slide_fingers.PAD_PUCK_CONTACT


# ---------------------------------------------------------------- the reference (MuJoCo C)


def run_reference(starts: dict) -> dict:
    import mujoco

    from splid_jax.reference.extra import make_reference
    from splid_jax.reference.mapping import reference_start

    sc = scripted()
    env = make_reference("slide")  # FetchSlide-v4, with the package's fix for MuJoCo releases after 3.11
    u_env = env.unwrapped
    m, d = u_env.model, u_env.data
    fingers = {m.geom(f"robot0:{s}_gripper_finger_link").id for s in ("l", "r")}
    puck, site = m.geom("object0").id, m.site("robot0:grip").id
    dof = int(m.joint("object0:joint").dofadr[0])
    q = int(m.joint("object0:joint").qposadr[0])
    out = []
    for i in range(len(starts["goal"])):
        env.reset(seed=i)
        shift = np.asarray(u_env.initial_gripper_xpos[:3]) - starts["grip_home"]
        shift[2] = float(u_env.height_offset) - float(starts["object_rest_z"])
        obs = reference_start(env, starts["object_xy"][i] + shift[:2], starts["goal"][i] + shift)
        trace = {"touch": [], "pxy": [], "pvel": [], "grip": [], "pose": []}

        def substeps(_action, trace=trace):
            for _ in range(u_env.n_substeps):
                mujoco.mj_step(m, d)
                trace["touch"].append(any({c.geom1, c.geom2} & fingers and puck in (c.geom1, c.geom2)
                                          for c in d.contact[: d.ncon]))  # fmt: skip
                trace["pxy"].append(d.qpos[q : q + 2].copy())
                trace["pvel"].append(d.qvel[dof : dof + 2].copy())
                trace["grip"].append(d.site_xpos[site][:2].copy())
                trace["pose"].append(d.qpos[q + 2 : q + 7].copy())

        u_env._mujoco_step = substeps
        start, goal = obs["achieved_goal"][:2].copy(), obs["desired_goal"][:2].copy()
        any_ok = False
        for _ in range(env.spec.max_episode_steps):
            act = np.asarray(sc.slide(obs["observation"], obs["desired_goal"], **SLIDE), np.float64)
            obs, _, _, _, info = env.step(act)
            any_ok |= bool(info["is_success"])
        uv = np.asarray(sc.launch_velocity(np.asarray(goal - start, np.float32)[None], DECEL))[0]
        uv = uv / max(np.linalg.norm(uv), 1e-9)
        dt = float(m.opt.timestep)
        tr = {k: np.asarray(v, np.float64) for k, v in trace.items()}
        t = np.arange(len(tr["touch"])) * dt + dt
        gvel = np.gradient(tr["grip"], dt, axis=0)
        out.append(episode_stats(t, tr["touch"].astype(bool), tr["pxy"], tr["pvel"], gvel, uv, any_ok,
                                 bool(info["is_success"]), start, goal, u_env.n_substeps, tr["pose"]))  # fmt: skip
    env.close()
    return {"mujoco": mujoco.__version__, "timestep": float(m.opt.timestep), "episodes": out}


# ---------------------------------------------------------------- summary


def stats(episodes: list[dict]) -> dict:
    res = {"episodes": len(episodes)}
    for k in KEYS:
        x = np.array([e[k] for e in episodes], float)
        if k.startswith("success"):
            res[k] = round(float(np.mean(x)), 3)
        else:
            x = x[np.isfinite(x)]
            res[k] = [round(float(v), 4) for v in np.quantile(x, (0.25, 0.5, 0.75))] if len(x) else None
    return res


def sudden_slowings(e: dict, loss: float = 0.06) -> int:
    """Control steps in which a puck sliding free (no touch in this step or the one before, faster than 0.05 m/s)
    slows by more than ``loss`` (m/s); the table's friction alone takes 0.04 at most."""
    if "sudden_slowings" in e:  # a trimmed record (``trim``)
        return e["sudden_slowings"]
    v, touch = np.asarray(e["speed_per_step"]), np.asarray(e["touch_per_step"])
    free = (touch[1:] == 0) & (touch[:-1] == 0) & (v[:-1] > 0.05)
    return int(np.sum(free & (np.diff(v) < -loss)))


def summarise(files: list[str]) -> None:
    """A markdown row per file: medians [quartiles] over its episodes; the grip's speed kept through the first
    touch (after / before), the episodes touched more than once, the launch's angle off the wanted line, the
    episodes with a sudden slowing (``sudden_slowings``)."""

    def q(x, fmt=".3f"):
        x = np.asarray(x, float)
        x = x[np.isfinite(x)]
        a, b, c = np.quantile(x, (0.25, 0.5, 0.75))
        return f"{b:{fmt}} [{a:{fmt}}, {c:{fmt}}]"

    head = ("grip at the touch (m/s)", "puck as the first touch ends (m/s)", "grip kept", "first touch (ms)",
            "touched again", "launch angle, abs (deg)", "puck after the last touch (m/s)", "slid after it (m)",
            "sudden slowings", "success any / final")  # fmt: skip
    print("| run | " + " | ".join(head) + " |")
    print("|---|" + "---|" * len(head))
    for f in files:
        r = read(f)
        e = {k: np.array([x[k] for x in r["episodes"]], float) for k in KEYS}
        cells = [q(e["v_grip"], ".2f"), q(e["v_first"], ".2f"), q(e["v_grip_after"] / e["v_grip"], ".2f"),
                 q(e["first_contact_s"] * 1e3, ".0f"), f"{np.mean(e['touches'] > 1):.2f}",
                 q(np.abs(e["dir_first"]), ".1f"), q(e["v_last"], ".2f"), q(e["slid"], ".2f"),
                 str(sum(sudden_slowings(x) > 0 for x in r["episodes"])),
                 f"{np.mean(e['success_any']):.2f} / {np.mean(e['success_final']):.2f}"]  # fmt: skip
        print(f"| {r['label']} | " + " | ".join(cells) + " |")


def read(path: str) -> dict:
    with (gzip.open if path.endswith(".gz") else open)(path, "rt") as fh:
        return json.load(fh)


def write(path: str, result: dict) -> None:
    """Floats to 4 digits, gzipped where ``path`` ends in .gz."""
    for e in result["episodes"]:
        e.update({k: round(v, 4) for k, v in e.items() if isinstance(v, float)})
    with (gzip.open if path.endswith(".gz") else open)(path, "wt") as fh:
        json.dump(result, fh, separators=(",", ":"))


def trim(files: list[str]) -> None:
    """Each episode's per-step speed and touch replaced by its count of sudden slowings, in place."""
    for f in files:
        r = read(f)
        for e in r["episodes"]:
            e["sudden_slowings"] = sudden_slowings(e)
            e.pop("speed_per_step", None)
            e.pop("touch_per_step", None)
        write(f, r)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("side", choices=("ours", "reference", "summarise", "trim"))
    p.add_argument("files", nargs="*")
    p.add_argument("--episodes", type=int, default=100)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--starts", help="npz: written by ours, read by the reference")
    p.add_argument("--env-options", default="finger=pads,finger_table=1,drive=weld,gripper_mass=22")
    p.add_argument("--pair", action="append", default=[], metavar="ATTR=VALUE")
    p.add_argument("--puck-friction", type=float, default=None)
    p.add_argument("--armature", default=None, help="x,y,z: armature (kg) on the gripper's slide joints")
    p.add_argument("--pads-symmetric", action="store_true", help="the pads' centres mirrored about the grip site")
    p.add_argument("--pad-xy", default=None, help="x,y: the pads' centres at (x, +-y) about the grip site")
    p.add_argument("--weld-solref", default=None, help='the weld drive\'s solref (models.WELD_SOLREF), e.g. "0.01 1"')
    p.add_argument("--aim-short", type=float, default=0.0, help="the strike aimed to stop this fraction short (slower)")
    p.add_argument("--label", default=None)
    p.add_argument("--out")
    a = p.parse_args(argv)
    if a.side in ("summarise", "trim"):
        (summarise if a.side == "summarise" else trim)(a.files)
        return 0
    SLIDE.update(aim_short=a.aim_short) if a.aim_short else None
    if a.side == "ours":
        from splid_jax.common.values import parse_overrides

        arm = [float(v) for v in a.armature.split(",")] if a.armature else None
        pad_xy = tuple(float(v) for v in a.pad_xy.split(",")) if a.pad_xy else None
        patch_pair(a.pair, a.puck_friction, a.weld_solref, arm, a.pads_symmetric, pad_xy)
        res, saved = run_ours(parse_overrides(a.env_options), a.episodes, a.seed)
        res.update(
            env_options=a.env_options,
            pair_patch=a.pair,
            puck_friction=a.puck_friction,
            weld_solref=a.weld_solref,
            armature=a.armature,
            pads_symmetric=a.pads_symmetric,
            pad_xy=a.pad_xy,
        )
        if a.starts:
            np.savez(a.starts, **saved)
    else:
        with np.load(a.starts) as f:
            res = run_reference({k: f[k] for k in f.files})
    res["label"] = a.label or (a.side if a.side == "reference" else f"ours {a.env_options} {' '.join(a.pair)}")
    res["stats"] = stats(res["episodes"])
    print(json.dumps(res["stats"]))
    if a.out:
        write(a.out, res)
    return 0


if __name__ == "__main__":
    sys.exit(main())
