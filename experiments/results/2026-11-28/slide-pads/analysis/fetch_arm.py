"""Our Slide's gripper on the reference's arm, for MuJoCo C (``slide_arm_c.py``): the pads' gripper of ``models.mjcf``
mounted on the 7-joint Fetch arm of Gymnasium-Robotics' ``robot.xml`` (its bodies' inertials, joints, ranges,
damping and armature, from the torso lift down to the gripper link), pulled by the reference's 6-dof mocap weld on
the gripper link.

The arm has no geoms: in the reference none of its links touches the table or the puck under the press probes
(``reference_arm_collision_probe.py``); its only contact is its base resting on the floor. That contact matters: the
base stands on three slides whose damping (1e11) MuJoCo integrates outside the constraint solve, so the solver sees
the base held only by that soft contact. ``base`` chooses how the base is mounted here: ``"held"`` as the
reference's (the three slides with their damping, each held at its place by a soft joint equality in place of the
floor contact) or ``"fixed"`` (welded to the world).

The fingers carry the reference fingers' masses, fixed to the gripper link or on the reference's finger slides; the
pads are ``slide_fingers``' boxes at the reference fingers' place in the link's frame.
"""

from __future__ import annotations

import re

import numpy as np

BASES = ("fixed", "held")
WELD = 'solref="0.02 1" solimp="0.9 0.95 0.001 0.5 2"'  # the reference's mocap weld (shared.xml)
# The base where FetchSlide-v4's reset leaves it (its slides at 0.05, 0.48, 0), in our coordinates (the reference's
# less the 0.15 mm by which its grip home differs from ours).
BASE_POS = (0.3368972, 0.7439459, 0.0)
BASE_SLIDE_DAMPING, BASE_SLIDE_ARMATURE = 1e11, 1e-4
ROTATE_TO_LINK = "0.7071068 0 -0.7071068 0"  # the link's frame turned back to the world's at the Slide start
GRIP_IN_LINK = (0.02, 0.0, 0.0)  # the reference's grip site on its gripper link
# The pads' centres about the grip site in the link's upright frame (slide_fingers.PAD_CENTERS without the reset
# tilt, which the arm now gives).
PAD_CENTERS = ((0.0, 0.008, 0.02), (0.0, -0.0095, 0.02))

# name, parent, pos, inertial (mass, pos, quat, diaginertia), joint (type, axis, range or None, damping, armature,
# stiffness) or None: robot.xml's chain from the torso lift (the head lumped onto it, its joints left out)
_CHAIN = (
    ("robot0:torso_lift_link", "base", (-0.0869, 0, 0.3774),
     (10.7796, (-0.0013, -0.0009, 0.2935), (0.9993, -0.0006, 0.0336, 0.0185), (0.3365, 0.3354, 0.0943)),
     ("slide", (0, 0, 1), (0.0386, 0.3861), 1e7, 1.0, 0.0)),
    ("robot0:head_pan_link", "robot0:torso_lift_link", (0.0531, 0, 0.603),
     (2.2556, (0.0321, 0.0161, 0.039), (0.5148, 0.5451, -0.453, 0.4823), (0.0185, 0.0128, 0.0095)), None),
    ("robot0:head_tilt_link", "robot0:head_pan_link", (0.1425, 0, 0.058),
     (0.9087, (0.0081, 0.0025, 0.0113), (0.6458, 0.66, -0.274, 0.2689), (0.0063, 0.0059, 0.0014)), None),
    ("robot0:shoulder_pan_link", "robot0:torso_lift_link", (0.1195, 0, 0.3486),
     (2.5587, (0.0927, -0.0056, 0.0564), (-0.1364, 0.7624, -0.1562, 0.613), (0.009, 0.0086, 0.0041)),
     ("hinge", (0, 0, 1), (-1.6056, 1.6056), 50.0, 1.0, 0.0)),
    ("robot0:shoulder_lift_link", "robot0:shoulder_pan_link", (0.117, 0, 0.06),
     (2.6615, (0.1432, 0.0072, -0.0001), (0.4382, 0.4382, 0.555, 0.555), (0.0116, 0.0112, 0.0023)),
     ("hinge", (0, 1, 0), (-1.221, 1.518), 50.0, 1.0, 0.0)),
    ("robot0:upperarm_roll_link", "robot0:shoulder_lift_link", (0.219, 0, 0),
     (2.3311, (0.1165, 0.0014, 0), (-0.0136, 0.707, 0.0136, 0.707), (0.0047, 0.0045, 0.0019)),
     ("hinge", (1, 0, 0), None, 50.0, 1.0, 0.0)),
    ("robot0:elbow_flex_link", "robot0:upperarm_roll_link", (0.133, 0, 0),
     (2.1299, (0.1279, 0.0073, 0), (0.4332, 0.4332, 0.5589, 0.5589), (0.0086, 0.0084, 0.002)),
     ("hinge", (0, 1, 0), (-2.251, 2.251), 50.0, 1.0, 0.0)),
    ("robot0:forearm_roll_link", "robot0:elbow_flex_link", (0.197, 0, 0),
     (1.6563, (0.1097, -0.0266, 0), (-0.0715, 0.7035, 0.0715, 0.7035), (0.0035, 0.0031, 0.0015)),
     ("hinge", (1, 0, 0), None, 3.5247, 2.7538, 10.0)),
    ("robot0:wrist_flex_link", "robot0:forearm_roll_link", (0.1245, 0, 0),
     (1.725, (0.0882, 0.0009, -0.0001), (0.4895, 0.4895, 0.5103, 0.5103), (0.0042, 0.0042, 0.0018)),
     ("hinge", (0, 1, 0), (-2.16, 2.16), 50.0, 1.0, 0.0)),
    ("robot0:wrist_roll_link", "robot0:wrist_flex_link", (0.1385, 0, 0),
     (0.1354, (0.0095, 0.0004, -0.0002), (1, 0, 0, 0), (0.0001, 0.0001, 0.0001)),
     ("hinge", (1, 0, 0), None, 50.0, 1.0, 0.0)),
    ("robot0:gripper_link", "robot0:wrist_roll_link", (0.1664, 0, 0),
     (1.5175, (-0.09, -0.0001, -0.0017), (0, 0.7071, 0, 0.7071), (0.0024, 0.0019, 0.0013)), None),
)  # fmt: skip
# The base's own bodies (base link, fixed torso, estop, laser) as one mass on the held base's slides (it does not
# turn, so only the mass counts).
_BASE_INERTIAL = (83.4172, (0, 0, 0), (1, 0, 0, 0), (1.0, 1.0, 1.0))
# The reference's fingers: body (name, y on the link, joint axis), their mass and inertia, their joints (locked in
# Slide; jointed, each slide carries armature 100 and damping 1000 and stops at its closed limit)
FINGERS = (("robot0:r_gripper_finger_link", 0.0159, 1.0), ("robot0:l_gripper_finger_link", -0.0159, -1.0))
FINGER_INERTIAL = (4.0, (-0.01, 0, 0), (1, 0, 0, 0), (0.1, 0.1, 0.1))
FINGER_JOINT = 'range="0 0.05" damping="1000" armature="100" solreflimit="0.01 1" solimplimit="0.99 0.999 0.01"'
FINGER_MODES = ("fixed", "jointed")
# FetchSlide-v4's arm joints (qpos, qvel) as its reset leaves them: the arm still settling
HOME = {
    "robot0:torso_lift_joint": (0.001272545341775302, 0.003258212534644488),
    "robot0:shoulder_pan_joint": (0.013387273830064042, 0.007027027674279468),
    "robot0:shoulder_lift_joint": (-0.5761543133717093, -0.04920367150706157),
    "robot0:upperarm_roll_joint": (-0.005933583105975259, -0.005390828264059866),
    "robot0:elbow_flex_joint": (1.4145274843655014, 0.11739247721737732),
    "robot0:forearm_roll_joint": (-2.8936958289794524e-05, 0.0014194114864277266),
    "robot0:wrist_flex_joint": (0.6825597022975838, 0.11706503975091503),
    "robot0:wrist_roll_joint": (0.008747871773003854, 0.004202647673959371),
}
FINGER_HOME = {
    "robot0:r_gripper_finger_joint": (-3.4599195268290276e-06, 3.5171923515412014e-06),
    "robot0:l_gripper_finger_joint": (0.0016492530157144734, 0.002459340614794956),
}
BASE_SLIDES = ("robot0:slide0", "robot0:slide1", "robot0:slide2")


def _fmt(*xs: float) -> str:
    return " ".join(f"{x:.8g}" for x in xs)


def _body(name: str, pos, inertial, joint, inner: str, indent: str) -> str:
    mass, ipos, iquat, diag = inertial
    out = f'{indent}<body name="{name}" pos="{_fmt(*pos)}">\n'
    out += (f'{indent}  <inertial mass="{mass:.8g}" pos="{_fmt(*ipos)}" quat="{_fmt(*iquat)}" '
            f'diaginertia="{_fmt(*diag)}"/>\n')  # fmt: skip
    if joint is not None:
        kind, axis, rng, damping, armature, stiffness = joint
        limit = f' range="{_fmt(*rng)}"' if rng else ' limited="false"'
        out += (f'{indent}  <joint name="{name.replace("_link", "_joint")}" type="{kind}" axis="{_fmt(*axis)}"{limit}'
                f' damping="{damping:.8g}" armature="{armature:.8g}" stiffness="{stiffness:.8g}"/>\n')  # fmt: skip
    return out + inner + f"{indent}</body>\n"


def _tree(parent: str, gripper: str, indent: str) -> str:
    out = ""
    for name, up, pos, inertial, joint in _CHAIN:
        if up == parent:
            inner = _tree(name, gripper, indent + "  ")
            if name == "robot0:gripper_link":
                inner += gripper
            out += _body(name, pos, inertial, joint, inner, indent)
    return out


def _finger_bodies(pads: list[str], fingers: str) -> str:
    """The reference's two finger bodies on the gripper link; ``jointed``: on their slides, each carrying its pad
    (``pads``: the right's and the left's geom, placed here in the link's frame)."""
    mass, ipos, iquat, diag = FINGER_INERTIAL
    out = ""
    for (name, y, sign), pad in zip(FINGERS, pads, strict=True):
        out += f'        <body name="{name}" pos="0 {y:.8g} 0">\n'
        out += (f'          <inertial mass="{mass:.8g}" pos="{_fmt(*ipos)}" quat="{_fmt(*iquat)}" '
                f'diaginertia="{_fmt(*diag)}"/>\n')  # fmt: skip
        if fingers == "jointed":
            joint = name.replace("_link", "_joint")
            out += f'          <joint name="{joint}" type="slide" axis="0 {sign:.0f} 0" {FINGER_JOINT}/>\n'
            pad = re.sub(r' pos="[^"]*"', f' pos="0 {-np.sign(y) * 0.008:.8g} 0"', pad)
            pad = re.sub(r' size="([^ ]*) ([^ ]*) ([^"]*)"', r' size="\3 \2 \1"', pad)
            out += f"          {pad.strip()}\n"
        out += "        </body>\n"
    return out


def gripper_xml(pads: str) -> str:
    """Our gripper body (the grip site and the pads, ``pads``: their geoms as ``slide_fingers.mjcf`` writes them) on
    the gripper link, upright when the link points down."""
    return (f'        <body name="gripper" pos="{_fmt(*GRIP_IN_LINK)}" quat="{ROTATE_TO_LINK}">\n'
            f'          <site name="grip" pos="0 0 0" size="0.005"/>\n{pads}\n        </body>\n')  # fmt: skip


def robot_xml(base: str, gripper: str) -> str:
    """The robot's bodies from the base down, ``gripper`` inside the gripper link."""
    if base not in BASES:
        raise ValueError(f"base must be one of {BASES}, got {base!r}")
    chain = _tree("base", gripper, "      ")
    head = f'    <body name="robot0:base_link" pos="{_fmt(*BASE_POS)}">\n'
    if base == "held":
        mass, ipos, iquat, diag = _BASE_INERTIAL
        head += (f'      <inertial mass="{mass:.8g}" pos="{_fmt(*ipos)}" quat="{_fmt(*iquat)}" '
                 f'diaginertia="{_fmt(*diag)}"/>\n')  # fmt: skip
        for j, axis in zip(BASE_SLIDES, ("1 0 0", "0 1 0", "0 0 1"), strict=True):
            head += (f'      <joint name="{j}" type="slide" axis="{axis}" damping="{BASE_SLIDE_DAMPING:.8g}" '
                     f'armature="{BASE_SLIDE_ARMATURE:.8g}"/>\n')  # fmt: skip
    return head + chain + "    </body>\n"


def equalities(base: str) -> str:
    """The mocap weld on the gripper link (the reference's: 6 rows, the link's frame on the mocap's) and, for the
    held base, the joint equalities holding its slides."""
    out = f'    <weld body1="target" body2="robot0:gripper_link" relpose="0 0 0 1 0 0 0" {WELD}/>\n'
    if base == "held":
        out += "".join(f'    <joint joint1="{j}" polycoef="0 1 0 0 0"/>\n' for j in BASE_SLIDES)
    return out


def mjcf(slide_xml: str, base: str = "held", fingers: str = "fixed") -> str:
    """Our Slide MJCF with the pads and the weld drive (``models.mjcf("slide", finger="pads", drive="weld", ...)``)
    with its gripper on the reference's arm: the gripper body's slides, palm and actuators replaced by the arm, the
    connect constraint by the 6-dof weld; the pads on the gripper (``fingers="fixed"``) or on the reference's finger
    slides (``"jointed"``)."""
    if fingers not in FINGER_MODES:
        raise ValueError(f"fingers must be one of {FINGER_MODES}, got {fingers!r}")
    grip = re.search(r'    <body name="gripper" pos="[^"]*">\n(.*?)\n    </body>', slide_xml, re.S)
    connect = re.search(r"    <connect [^>]*/>\n", slide_xml)
    actuators = re.search(r"  <actuator>.*?</actuator>\n", slide_xml, re.S)
    if not (grip and connect and actuators) or 'name="pad_r"' not in grip.group(1):
        raise ValueError("not a Slide MJCF with the pads and the weld drive")
    pads = [ln for ln in grip.group(1).splitlines() if 'name="pad_' in ln]
    for i, c in enumerate(PAD_CENTERS):
        pads[i] = re.sub(r' pos="[^"]*"', f' pos="{_fmt(*c)}"', pads[i])
    on_grip = "\n".join("    " + p.strip() for p in pads) if fingers == "fixed" else ""
    body = robot_xml(base, gripper_xml(on_grip) + _finger_bodies(pads, fingers))
    xml = slide_xml.replace(grip.group(0) + "\n", body)
    xml = xml.replace(connect.group(0), equalities(base))
    return xml.replace(actuators.group(0), "")


def mocap_target(grip_target, link_pos, site_pos, link_quat) -> tuple[np.ndarray, np.ndarray]:
    """The mocap body's position and orientation for a grip-site ``grip_target`` (world), as the reference's
    ``mocap_set_action`` sets them: the link moved by the grip's step, its orientation target re-anchored to the
    link's own plus (1, 0, 1, 0), normalised."""
    q = np.asarray(link_quat) + np.array([1.0, 0.0, 1.0, 0.0])
    return np.asarray(grip_target) + np.asarray(link_pos) - np.asarray(site_pos), q / np.linalg.norm(q)
