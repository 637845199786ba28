"""MJCF models of the Fetch-style tasks, written for MJX: a gripper, a table and an object.

Every geom is a primitive with ``contype = conaffinity = 0``; the only collisions are the
``<contact><pair>`` entries, so MJX evaluates exactly those.

- Gripper: a body on three world-aligned slide joints, each driven by a position actuator
  (kp = m w^2, w = 50 rad/s) with critical joint damping 2 m w, so it follows its target as the
  reference's mocap weld (solref 0.02 1, the same time constant) follows its mocap body; the z
  actuator carries ``m g`` as gravity compensation. Slide joints rather than a welded free body
  because the weld adds 3 dofs and 6 constraint rows and ran slower in MJX; the damping, integrated
  implicitly, keeps the drive stable at long timesteps. ``drive="weld"`` pulls the same joints by
  the reference's weld law instead (a connect constraint to a mocap body).
- Reach: the reference's gripper hangs on a 7-joint arm, ours on none, so ``control.within_reach`` keeps the
  target within the arm's measured reach (task field ``workspace``); only Slide's goals exceed it.
- Fingers: one fixed closed block for Reach, Push and Slide; for PickAndPlace two slide joints with
  position actuators (kp 30000, range 0..0.05) and, by default, the reference's joint armature and damping
  (``FINGER_DRIVES``). With ``finger_table`` (Push's default)
  they reach as far down as the reference's and press and drag on the table as its fingers do.
- Table: its top face is a plane at z = 0.4, a cheaper contact than the reference's box
  (``table="box"`` gives the box). An object pushed past an edge glides on instead of falling; every
  goal lies on or above the table, so such an episode fails on both.
- Slide: the reference's cylinder puck (radius 0.025, half-height 0.02, mass 2, friction 0.1 on the
  table). Stock MJX collides a cylinder with a sphere but not with a box, so by default the closed fingers
  strike it with four round corner tips; ``finger="pads"`` gives the reference's two box pads, collided by
  ``envs/box_cylinder.py`` (``slide_fingers``). The gripper weighs 13 kg, the reference arm's effective mass at the
  grip site; lighter, it launches the puck too slowly.
- ``finger="pads"`` (Push's default): the block has the horizontal extent of the reference's two closed
  finger pads at the cube's height (``PADS_HALF_XY``), so a push moves the cube as far as there;
  ``"box"`` is a smaller block, ``"capsule"`` that block as a capsule, a cheaper contact.

How these compare with the reference: ``experiments/parity/README.md``.
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools

import mujoco
import numpy as np

from envs.fetch import slide_fingers
from envs.fetch.control import ARM_REACH_CENTER, ARM_REACH_CENTER_DEFAULT

TABLE_TOP = 0.4
OBJECT_HALF = 0.025
PUCK_HALF_HEIGHT = 0.02
FINGER_BELOW_SITE = 0.008  # the fingertips reach this far below the grip site
# With a finger-table contact (``finger_table`` > 0) the fingertips reach as far down as the reference's, which
# touch its table with the grip site at 0.416 to 0.420 (2 to 3 mm into it at the Push start, grip at 0.416).
REFERENCE_FINGER_BELOW_SITE = 0.019
# How far below the fingertips-on-the-table height the target may go with that contact: the press that, at
# the reference's finger friction 1, drags the gripper as the reference's mocap weld drags its fingers.
FINGER_PRESS = 0.025
# Half extents (x, y) of the reference's two closed finger pads taken together, cut at the cube's mid-height
# (x -0.0139..0.0132, y -0.0160..0.0149 about its grip site): the closed finger block with ``finger="pads"``.
PADS_HALF_XY = (0.0135, 0.0155)
# Their contact with the cube as MuJoCo mixes the two geoms' (a pad: condim 4, friction 1 0.05 0.01, margin
# 0.001, solref 0.01 1, solimp 0.99 0.99 0.01; the cube: the defaults): stiffer than the default contact,
# with torsional friction, and active 1 mm before touching.
PADS_OBJECT_CONTACT = ('condim="4" friction="1 1 0.05 0.01 0.01" margin="0.001" solref="0.015 1" '
                       'solimp="0.945 0.97 0.0055 0.5 2"')
GRIPPER_MASS = 4.0  # palm + fingers, the mass the xyz drive moves
DRIVE_OMEGA = 50.0  # rad/s: the reference weld's time constant 0.02 s
FINGER_KP = 30000.0
FINGER_MASS = 1.0
# How PickAndPlace's finger joints respond to their position actuators (kp 30000 as the reference's):
# "reference" as the reference's joints, whose 4 kg fingers carry an armature of 100 and a damping of 1000
# (about 17 rad/s, underdamped: they close in about 0.1 s); "fast" 1 kg fingers, critically damped, without
# armature (173 rad/s), which slam shut at up to about 8 m/s and under exploration noise throw the cube
# (experiments/NOTES.md, "PickAndPlace's fingers").
FINGER_DRIVES = ("reference", "fast")
REFERENCE_FINGER_INERTIA = 104.0  # kg along the joint: the reference finger's 4 kg and its armature of 100
REFERENCE_FINGER_DAMPING = 1000.0
# Slide only (see the module docstring): the reference arm's effective mass at the grip site (its fingers:
# envs/fetch/slide_fingers.py).
SLIDE_GRIPPER_MASS = 13.0

# kind -> (table centre xyz, table half-size xyz, initial grip-site position). The start positions
# are those the reference's episodes begin from (read off its resets in experiments/parity): Push
# and Slide start with the gripper down at the table (gripper_extra_height 0 and -0.02), Reach and
# PickAndPlace 0.2 higher than that rest height.
_SCENES = {
    "reach": ((1.3, 0.75, 0.2), (0.25, 0.35, 0.2), (1.342, 0.749, 0.535)),
    "push": ((1.3, 0.75, 0.2), (0.25, 0.35, 0.2), (1.363, 0.749, 0.416)),
    "pick_and_place": ((1.3, 0.75, 0.2), (0.25, 0.35, 0.2), (1.342, 0.749, 0.535)),
    "slide": ((1.32, 0.75, 0.2), (0.625, 0.45, 0.2), (1.013, 0.749, 0.416)),
}
KINDS = tuple(_SCENES)


DRIVES = ("pd", "weld")
WELD_SOLREF = "0.02 1"  # the reference's mocap weld: time constant, damping ratio
WELD_SOLIMP = "0.9 0.95 0.001 0.5 2"


def workspace_box(kind: str, finger_table: float = 0.0, press: float = FINGER_PRESS):
    """World xyz (lo, hi) of the box the gripper target is clipped to: the table and 15 cm around it in
    xy, from the fingertips on the table top to 0.6 m above it. With a finger-table contact the floor is
    ``press`` below the fingertips on the table: there the table, not the box, stops the gripper,
    and a downward command presses it on the table and drags it as in the reference."""
    (tx, ty, _), (hx, hy, _), _ = _SCENES[kind]
    margin = 0.15
    floor = TABLE_TOP + (REFERENCE_FINGER_BELOW_SITE - press if finger_table > 0 else FINGER_BELOW_SITE)
    return ((tx - hx - margin, ty - hy - margin, floor),
            (tx + hx + margin, ty + hy + margin, TABLE_TOP + 0.6))


TABLES = ("plane", "box")
EDGED = "edged"  # Slide's plane top ending at the reference table's edges (envs/fetch/table_edge.py)


def tables_for(kind: str) -> tuple[str, ...]:
    """The table shapes task ``kind`` can use: MJX collides Slide's cylinder puck with a plane only."""
    return ("plane", EDGED) if kind == "slide" else TABLES


def fingers_for(kind: str) -> tuple[str, ...]:
    """Collision shapes of the closed finger block: Push may use the reference pads' extent
    (``PADS_HALF_XY``), a smaller box, or a vertical capsule of the box's height (radius 1.1 cm); Slide
    strikes with round tips or the reference's two pads (``slide_fingers``), PickAndPlace grips with two box
    fingers, Reach touches nothing."""
    return ("pads", "box", "capsule") if kind == "push" else slide_fingers.FINGERS if kind == "slide" else ("box",)


@dataclasses.dataclass(frozen=True)
class Layout:
    """Where things live in ``qpos``/``qvel``/``ctrl``, as Python ints (static under jit)."""

    grip_q: int  # qpos/qvel address of the gripper's x slide (y, z follow)
    finger_q: int | None  # qpos address of the left finger (right follows); None when fixed
    finger_v: int | None
    object_q: int | None  # qpos address of the object's free joint; None for Reach
    object_v: int | None
    grip_home: tuple[float, float, float]  # grip-site position when the gripper joints are 0
    workspace_lo: tuple[float, float, float]  # clip box of the grip-site target
    workspace_hi: tuple[float, float, float]
    reach_center: tuple[float, float, float]  # centre of the reference arm's reach (ARM_REACH_*)
    object_rest_z: float | None  # object centre height at rest on the table
    nq: int
    nv: int
    nu: int


def _fmt(*xs: float) -> str:
    return " ".join(f"{x:.6g}" for x in xs)


def mjcf(
    kind: str,
    timestep: float = 0.002,
    iterations: int = 4,
    ls_iterations: int = 4,
    table: str = "plane",
    finger: str = "box",
    *,
    gripper_mass: float | None = None,
    drive_omega: float = DRIVE_OMEGA,
    drive_damping_ratio: float = 1.0,
    drive_damping: str = "joint",
    drive: str = "pd",
    finger_table: float = 0.0,
    finger_drive: str = "reference",
    hand_pitch: float = 0.0,
) -> str:
    """The MJCF text of task ``kind`` (one of ``KINDS``); ``table`` is the table's collision shape
    (``tables_for(kind)``), ``finger`` the closed finger block's (``fingers_for(kind)``).

    ``gripper_mass`` (default: the task's), ``drive_omega`` and ``drive_damping_ratio`` change the xyz
    drive (kp = m w^2, damping 2 z m w) for sensitivity studies (``experiments/parity/slide_strike.py``).
    ``drive_damping`` is where that damping acts: ``"joint"`` (default) as joint damping, which the Euler
    integrator treats implicitly; ``"actuator"`` as the actuators' velocity feedback, explicit like the
    damping term of the reference weld's reference acceleration.

    ``drive="weld"`` holds the gripper to a mocap body ``target`` (the grip site's world target) by a
    connect constraint with the reference weld's solref and solimp (``WELD_SOLREF``, ``WELD_SOLIMP``)
    instead of the PD drive: the reference's drive law on our gripper. Whoever steps the model puts the
    mocap body at the grip site's target (the tasks' field ``drive``, ``experiments/parity/slide_c.py``);
    ``ctrl[0:3]`` then moves nothing.

    ``finger_table`` > 0: the fingers reach ``REFERENCE_FINGER_BELOW_SITE``
    below the grip site and touch the table with this friction (condim 3), so a gripper driven down at
    the table presses on it and drags, as the reference's does under its mocap weld; 0: no such contact.

    ``finger_drive`` (PickAndPlace's free fingers): one of ``FINGER_DRIVES``, see there. ``hand_pitch`` (Slide's
    pads): a custom numeric by which ``envs/fetch/hand_pitch.py`` pitches them as the reference arm stretches;
    ``table="edged"`` (Slide) one with the table's x-y extent, where ``envs/fetch/table_edge.py`` ends the top."""
    if kind not in _SCENES:
        raise ValueError(f"unknown kind {kind!r}: one of {KINDS}")
    if table not in tables_for(kind):
        raise ValueError(f"table {table!r} for {kind}: one of {tables_for(kind)}")
    if finger not in fingers_for(kind):
        raise ValueError(f"finger {finger!r} for {kind}: one of {fingers_for(kind)}")
    for name, value in (("gripper_mass", gripper_mass), ("drive_omega", drive_omega),
                        ("drive_damping_ratio", drive_damping_ratio)):
        if value is not None and not value > 0:
            raise ValueError(f"{name} must be > 0, got {value}")
    if drive_damping not in ("joint", "actuator"):
        raise ValueError(f"drive_damping must be 'joint' or 'actuator', got {drive_damping!r}")
    if drive not in DRIVES:
        raise ValueError(f"drive must be one of {DRIVES}, got {drive!r}")
    if finger_drive not in FINGER_DRIVES:
        raise ValueError(f"finger_drive must be one of {FINGER_DRIVES}, got {finger_drive!r}")
    if finger_table < 0:
        raise ValueError(f"finger_table must be >= 0, got {finger_table}")
    if hand_pitch and not (kind == "slide" and finger == "pads" and hand_pitch > 0):
        raise ValueError(f"hand_pitch must be 0 but on Slide's pads, and > 0 there, got {hand_pitch}")
    (tx, ty, tz), (hx, hy, hz), (gx, gy, gz) = _SCENES[kind]
    has_object = kind != "reach"
    free_fingers = kind == "pick_and_place"
    slide = kind == "slide"
    mass = gripper_mass if gripper_mass is not None else SLIDE_GRIPPER_MASS if slide else GRIPPER_MASS
    w = drive_omega
    kp, kv = mass * w * w, 2.0 * drive_damping_ratio * mass * w
    joint_kv, bias_kv = (f"{kv:.6g}", "0") if drive_damping == "joint" else ("0", f"{-kv:.6g}")
    weld = target_body = ""
    if drive == "weld":  # no PD forces (the z actuator keeps only the gravity bias); a constraint pulls instead
        kp, joint_kv, bias_kv = 0.0, "0", "0"
        target_body = f'<body name="target" mocap="true" pos="{_fmt(gx, gy, gz)}"/>'
        weld = f"""
  <equality>
    <connect body1="gripper" body2="target" anchor="0 0 0" solref="{WELD_SOLREF}" solimp="{WELD_SOLIMP}"/>
  </equality>"""
    obj_half = (OBJECT_HALF, OBJECT_HALF, PUCK_HALF_HEIGHT if slide else OBJECT_HALF)
    rest_z = TABLE_TOP + obj_half[2]
    ox, oy = gx + 0.1, gy + 0.1  # any spot on the table; reset moves it
    below = REFERENCE_FINGER_BELOW_SITE if finger_table > 0 else FINGER_BELOW_SITE
    finger_z = 0.03 - below  # finger box half-height 0.03, bottom ``below`` the grip site
    palm_mass = mass - (2 * FINGER_MASS if free_fingers else 0.0)
    friction = "0.1 0.1 0.005 0.0001 0.0001" if slide else "1 1 0.005 0.0001 0.0001"
    nograv = 'contype="0" conaffinity="0"'
    edged, plane_top = table == EDGED, table in ("plane", EDGED)
    table = f"""<geom name="table" type="box" pos="{_fmt(tx, ty, tz)}" size="{_fmt(hx, hy, hz)}" {nograv}
          rgba="0.6 0.5 0.4 1"/>"""
    if plane_top:  # the top face as a plane: a cheaper contact than box-box, and MJX's only one for a cylinder
        table = f"""<geom name="table" type="plane" pos="{_fmt(tx, ty, TABLE_TOP)}" size="{_fmt(hx, hy)} 0.1" {nograv}
          rgba="0.6 0.5 0.4 1"/>
    <geom name="table_body" type="box" pos="{_fmt(tx, ty, tz)}" size="{_fmt(hx, hy, hz - 0.001)}" {nograv}
          rgba="0.6 0.5 0.4 1"/>"""

    if free_fingers:
        if finger_drive == "reference":
            fdamp, armature = REFERENCE_FINGER_DAMPING, REFERENCE_FINGER_INERTIA - FINGER_MASS
        else:
            fdamp, armature = 2.0 * FINGER_MASS * np.sqrt(FINGER_KP / FINGER_MASS), 0.0
        fjoint = f'type="slide" range="0 0.05" damping="{fdamp:.6g}" armature="{armature:.6g}"'
        fingers = f"""
      <body name="finger_l">
        <joint name="finger_l" axis="0 1 0" {fjoint}/>
        <geom name="finger_l" type="box" size="0.01 0.006 0.03" pos="0 0.006 {finger_z:.6g}"
              mass="{FINGER_MASS}" {nograv} rgba="0.3 0.3 0.3 1"/>
      </body>
      <body name="finger_r">
        <joint name="finger_r" axis="0 -1 0" {fjoint}/>
        <geom name="finger_r" type="box" size="0.01 0.006 0.03" pos="0 -0.006 {finger_z:.6g}"
              mass="{FINGER_MASS}" {nograv} rgba="0.3 0.3 0.3 1"/>
      </body>"""
        finger_act = f"""
    <position name="finger_l" joint="finger_l" kp="{FINGER_KP:.6g}" ctrlrange="0 0.2"/>
    <position name="finger_r" joint="finger_r" kp="{FINGER_KP:.6g}" ctrlrange="0 0.2"/>"""
        finger_pairs = """
    <pair geom1="finger_l" geom2="object" condim="4" friction="1 1 0.005 0.0001 0.0001"/>
    <pair geom1="finger_r" geom2="object" condim="4" friction="1 1 0.005 0.0001 0.0001"/>"""
    elif slide:
        look = f'{nograv} rgba="0.3 0.3 0.3 1"'
        fingers, finger_pairs, table_fingers = slide_fingers.mjcf(finger, below, finger_table, look)
        finger_act = ""
    else:
        shape = {
            "capsule": 'type="capsule" size="0.011 0.019"',
            "box": 'type="box" size="0.01 0.012 0.03"',
            "pads": f'type="box" size="{_fmt(*PADS_HALF_XY)} 0.03"',
        }[finger]
        fingers = f"""
      <geom name="fingers" {shape} pos="0 0 {finger_z:.6g}" mass="0.001"
            {nograv} rgba="0.3 0.3 0.3 1"/>"""
        finger_act = ""
        contact = PADS_OBJECT_CONTACT if finger == "pads" else f'condim="3" friction="{friction}"'
        finger_pairs = (
            f"""
    <pair geom1="fingers" geom2="object" {contact}/>"""
            if has_object
            else ""
        )

    obj = ""
    obj_pairs = ""
    if has_object:
        size = _fmt(OBJECT_HALF, PUCK_HALF_HEIGHT) if slide else _fmt(*obj_half)
        shape = f'type="{"cylinder" if slide else "box"}" size="{size}"'
        obj = f"""
    <body name="object" pos="{_fmt(ox, oy, rest_z)}">
      <freejoint name="object"/>
      <geom name="object" {shape} mass="2" {nograv} rgba="0.9 0.2 0.2 1"/>
      <site name="object" pos="0 0 0" size="0.005"/>
    </body>"""
        obj_pairs = f"""
    <pair geom1="object" geom2="table" condim="3" friction="{friction}"/>"""
        if not plane_top or edged:  # on an infinite plane top the object cannot fall to the floor
            obj_pairs += """
    <pair geom1="object" geom2="floor" condim="3"/>"""

    if finger_table > 0:
        names = ("finger_l", "finger_r") if free_fingers else table_fingers if slide else ("fingers",)
        finger_pairs += "".join(
            f"""
    <pair geom1="{n}" geom2="table" condim="3" friction="{finger_table:.6g} {finger_table:.6g} 0.005 0.0001 0.0001"/>"""
            for n in names
        )

    edge = [tx - hx, tx + hx, ty - hy, ty + hy] * edged
    numerics = {"hand_pitch": [hand_pitch] * bool(hand_pitch), "table_edge": edge}
    custom = "".join(f'<numeric name="{k}" data="{_fmt(*v)}"/>' for k, v in numerics.items() if v)
    custom = f"\n  <custom>{custom}</custom>" if custom else ""
    return f"""<mujoco model="fetch_{kind}">
  <compiler angle="radian" autolimits="true"/>{custom}
  <option timestep="{timestep:.6g}" integrator="Euler" solver="Newton" iterations="{iterations}"
          ls_iterations="{ls_iterations}" cone="pyramidal"/>
  <worldbody>
    <geom name="floor" type="plane" size="3 3 0.1" {nograv} rgba="0.8 0.8 0.8 1"/>
    {table}
    <body name="gripper" pos="{_fmt(gx, gy, gz)}">
      <joint name="grip_x" type="slide" axis="1 0 0" damping="{joint_kv}"/>
      <joint name="grip_y" type="slide" axis="0 1 0" damping="{joint_kv}"/>
      <joint name="grip_z" type="slide" axis="0 0 1" damping="{joint_kv}"/>
      <site name="grip" pos="0 0 0" size="0.005"/>
      <geom name="palm" type="box" size="0.02 0.04 0.01" pos="0 0 0.062" mass="{palm_mass:.6g}" {nograv}
            rgba="0.3 0.3 0.3 1"/>{fingers}
    </body>{obj}{target_body}
  </worldbody>{weld}
  <contact>{obj_pairs}{finger_pairs}
  </contact>
  <actuator>
    <general name="grip_x" joint="grip_x" gainprm="{kp:.6g}" biastype="affine" biasprm="0 {-kp:.6g} {bias_kv}"/>
    <general name="grip_y" joint="grip_y" gainprm="{kp:.6g}" biastype="affine" biasprm="0 {-kp:.6g} {bias_kv}"/>
    <general name="grip_z" joint="grip_z" gainprm="{kp:.6g}" biastype="affine"
             biasprm="{mass * 9.81:.6g} {-kp:.6g} {bias_kv}"/>{finger_act}
  </actuator>
</mujoco>
"""


def rest_height(m: mujoco.MjModel, object_q: int) -> float:
    """Height at which the object comes to rest on the table (contacts are soft: it sinks a little)."""
    d = mujoco.MjData(m)
    for _ in range(int(round(1.0 / m.opt.timestep))):
        mujoco.mj_step(m, d)
    return float(d.qpos[object_q + 2])


def own_contacts(m: mujoco.MjModel):
    """The block within which MJX knows the contacts model ``m`` needs and it lacks (box-cylinder:
    ``envs/box_cylinder.py``); put_model, make_data and a step's trace of ``m`` must run inside it."""
    from envs.fetch.kernels import model_contacts

    groups = model_contacts(m)
    if not groups:
        return contextlib.nullcontext()
    from envs import mjx_patch

    return mjx_patch.patched_mjx(collide=groups)


@functools.cache
def build(kind: str, **options):
    """``(mj_model, mjx_model, layout)`` for task ``kind`` with ``mjcf``'s keyword ``options``; cached,
    so tasks stay hashable."""
    from envs.base import put_model

    m = mujoco.MjModel.from_xml_string(mjcf(kind, **options))
    jnt = lambda name: m.joint(name)  # noqa: E731
    grip_q = int(jnt("grip_x").qposadr[0])
    free_fingers = kind == "pick_and_place"
    finger_q = int(jnt("finger_l").qposadr[0]) if free_fingers else None
    finger_v = int(jnt("finger_l").dofadr[0]) if free_fingers else None
    object_q = int(jnt("object").qposadr[0]) if kind != "reach" else None
    object_v = int(jnt("object").dofadr[0]) if kind != "reach" else None
    home = _SCENES[kind][2]
    lo, hi = workspace_box(kind, options.get("finger_table", 0.0))
    rest_z = rest_height(m, object_q) if object_q is not None else None
    layout = Layout(
        grip_q=grip_q,
        finger_q=finger_q,
        finger_v=finger_v,
        object_q=object_q,
        object_v=object_v,
        grip_home=tuple(float(x) for x in home),
        workspace_lo=lo,
        workspace_hi=hi,
        reach_center=ARM_REACH_CENTER.get(kind, ARM_REACH_CENTER_DEFAULT),
        object_rest_z=rest_z,
        nq=int(m.nq),
        nv=int(m.nv),
        nu=int(m.nu),
    )
    with own_contacts(m):
        return m, put_model(m, impl="jax"), layout
