"""Scripted controllers for the Fetch-style tasks, on the reference observation layout.

Each controller is a pure, stateless function ``controller(obs, goal) -> action``: the phase of the
motion (approach, descend, push, grasp, carry) is read off the observation alone, so the functions
jit, vmap and broadcast over any leading batch dimensions. They take numpy or jax arrays and return a
``jax.Array`` of 4 floats in [-1, 1] (``a[3]`` drives the fingers; the locked-gripper tasks ignore it).

Observation layout (25 floats; Reach uses only ``obs[0:3]``): ``[0:3]`` gripper position, ``[3:6]``
object position, ``[6:9]`` object - gripper, ``[9:11]`` finger joint positions, ``[11:14]`` object
Euler angles, ``[14:17]`` object - gripper linear velocity, ``[17:20]`` object angular velocity,
``[20:23]`` gripper linear velocity, ``[23:25]`` finger velocities; velocities are per control step.

An action moves the gripper target by ``MAX_STEP * a[:3]`` metres from where the gripper is, so
``a = (target - grip) / MAX_STEP`` (clipped) heads for ``target`` at up to ``MAX_STEP`` per step.
"""

from __future__ import annotations

import jax.numpy as jnp

MAX_STEP = 0.05  # metres of gripper target motion per unit action per control step
DT = 0.04  # seconds per control step
GRAVITY = 9.81

CUBE_HALF = 0.025  # Push / PickAndPlace object half-size
CONTACT_OFFSET = 0.06  # gripper centre behind the object's centre when lined up to push
CLEARANCE = 0.07  # gripper height above the object's centre that passes over it
SLIDE_MAX_SPEED = 2.0  # m/s cap on the commanded slide push speed
LINE_TOL = 0.012  # xy tolerance for "lined up behind the object" before descending


def _parts(obs, goal):
    obs = jnp.asarray(obs, jnp.float32)
    goal = jnp.asarray(goal, jnp.float32)
    return obs, obs[..., 0:3], obs[..., 3:6], goal


def _toward(grip, target, gain=1.0):
    """Action that moves the gripper to ``target`` (as fast as allowed when ``gain`` is 1)."""
    return jnp.clip(gain * (target - grip) / MAX_STEP, -1.0, 1.0)


def _with_fingers(move, fingers):
    fingers = jnp.broadcast_to(jnp.asarray(fingers, move.dtype), move.shape[:-1])
    return jnp.concatenate([move, fingers[..., None]], axis=-1)


def _norm(v):
    return jnp.sqrt(jnp.sum(v * v, axis=-1, keepdims=True))


def _line_up(grip, obj, goal, offset, speed_xy):
    """Shared push/slide motion: go behind the object on the line goal->object, descend, advance.

    ``speed_xy(dist)`` is the gripper xy advance per step while pushing, given the object's distance
    to the goal (shape [..., 1]). Returns the 3-float move.
    """
    d = goal[..., :2] - obj[..., :2]
    dist = _norm(d)
    u = d / jnp.maximum(dist, 1e-6)
    behind = obj[..., :2] - u * offset
    rel = grip[..., :2] - obj[..., :2]
    along = jnp.sum(rel * u, axis=-1, keepdims=True)
    lateral = _norm(rel - along * u)
    low = grip[..., 2:3] < obj[..., 2:3] + 0.02
    low_z = obj[..., 2:3]
    safe_z = obj[..., 2:3] + CLEARANCE

    # Pushing: low, behind the object, close to the line; aim on the line, ahead of the contact point.
    pushing = low & (along < -0.02) & (along > -(offset + 0.04)) & (lateral < 0.02)
    advance = speed_xy(dist)
    push_xy = obj[..., :2] + u * (along + advance)  # along the line, from the gripper's projection
    push_target = jnp.concatenate([push_xy, low_z], axis=-1)
    push_move = jnp.clip((push_target - grip) / MAX_STEP, -1.0, 1.0)

    # Lined up above/at the behind point: descend there (a wider tolerance once low keeps it stable).
    off_xy = _norm(grip[..., :2] - behind)
    lined_up = off_xy < LINE_TOL + jnp.where(low, 0.008, 0.0)
    descend_move = _toward(grip, jnp.concatenate([behind, low_z], axis=-1))

    # Otherwise: rise to the safe height, and travel in xy only once high (or clear of the object).
    high = grip[..., 2:3] > safe_z - 0.02
    clear = _norm(rel) > offset + 0.03
    travel_xy = jnp.where(high | clear, behind, grip[..., :2])
    travel_move = _toward(grip, jnp.concatenate([travel_xy, safe_z], axis=-1))

    move = jnp.where(pushing, push_move, jnp.where(lined_up, descend_move, travel_move))
    done = dist < 0.01
    return jnp.where(done, 0.0, move)


def push(obs, goal):
    """Push the cube to ``goal``: behind it on the goal line at a safe height, descend, push."""
    _, grip, obj, goal = _parts(obs, goal)

    def speed(dist):  # slow down near the goal so the cube stops on it (friction 1 stops it at once)
        return jnp.minimum(dist, 0.03)

    return _with_fingers(_line_up(grip, obj, goal, CONTACT_OFFSET, speed), -1.0)


SLIDE_FRICTION = 0.1  # puck-table sliding friction of the Slide task
SLIDE_GAIN = 1.0  # scales the launch speed
SLIDE_PUSH_GAIN = 1.1  # commanded over wanted gripper speed while pushing (tuned on the reference)
PUCK_RADIUS = 0.025
# Half-extents (x, y) of the closed fingers' footprint around the grip site: a round puck pushed by a
# flat face goes off along the face normal, so the slide pushes with the footprint's corner, whose
# contact normal points from the corner to the puck's centre, i.e. along the aimed line.
FINGER_HALF_XY = (0.0155, 0.0155)
SLIDE_GAP = 0.03  # run-up between the corner and the puck before the push
SLIDE_CONTACT = 0.01  # corner-to-puck gap counted as contact


def launch_velocity(displacement, decel):
    """Puck velocity (xy) from which sliding friction alone carries it by ``displacement`` (xy).

    MuJoCo's default pyramidal friction cone acts per axis of the contact frame (world x, y for a puck
    on the table): the faster axis decelerates at ``decel`` while the slower one keeps its speed, until
    both are equal; then both decelerate at ``decel / 2``. Integrating gives, for |vx| >= |vy|,
    X = (vx^2 + vy^2) / (2 decel) and Y = vx vy / decel, which inverts in closed form below.
    """
    mag = jnp.abs(displacement)
    big = jnp.max(mag, axis=-1, keepdims=True)
    small = jnp.min(mag, axis=-1, keepdims=True)
    s = jnp.sqrt(2.0 * decel * (big + small))
    t = jnp.sqrt(2.0 * decel * jnp.maximum(big - small, 0.0))
    v_big, v_small = 0.5 * (s + t), 0.5 * (s - t)
    x_is_big = mag[..., 0:1] >= mag[..., 1:2]
    v = jnp.concatenate([jnp.where(x_is_big, v_big, v_small), jnp.where(x_is_big, v_small, v_big)], axis=-1)
    return v * jnp.sign(displacement)


def slide(
    obs,
    goal,
    gain=SLIDE_GAIN,
    friction=SLIDE_FRICTION,
    push_gain=SLIDE_PUSH_GAIN,
    approach_speed=0.2,
    aim_short=0.0,
    trail_gap=None,
):
    """Slide the puck to ``goal``: line up the fingers' corner behind it on the launch line (the
    direction of ``launch_velocity``, which bends with the friction cone), descend, close in slowly and
    push at the launch speed from which friction alone stops the puck on the goal. As the remaining
    distance shrinks the wanted speed drops, so the puck glides on alone; when it stops short the
    gripper, still on the line, catches up and pushes again.

    The re-push variant: ``aim_short`` (a fraction) launches the puck to stop that much of the way
    short, and ``trail_gap`` (metres) has the gripper follow a gliding puck that far behind, so it is
    at hand to push again where the puck stops. Whether that works depends on where the gripper can
    reach (``tasks`` field ``workspace``), which is what it was written to show (experiments/parity).
    """
    _, grip, obj, goal = _parts(obs, goal)
    d = goal[..., :2] - obj[..., :2]
    dist = _norm(d)
    v_launch = launch_velocity(d, friction * GRAVITY)
    speed = _norm(v_launch)
    u = v_launch / jnp.maximum(speed, 1e-6)
    speed = speed * jnp.sqrt(1.0 - aim_short)  # friction stops it (1 - aim_short) of the way
    corner = jnp.where(u >= 0, 1.0, -1.0) * jnp.asarray(FINGER_HALF_XY, jnp.float32)
    tip = grip[..., :2] + corner
    rel = tip - obj[..., :2]
    along = jnp.sum(rel * u, axis=-1, keepdims=True)
    lateral = _norm(rel - along * u)
    low = grip[..., 2:3] < obj[..., 2:3] + 0.02
    low_z = obj[..., 2:3]
    safe_z = obj[..., 2:3] + CLEARANCE

    # Following: low, behind the puck and on its line. Close the gap slowly (an impact would leave the
    # puck faster than the gripper), then, in contact, push at the launch speed while the puck is
    # slower than that, and hold still once it is not.
    following = low & (along < -0.01) & (lateral < 0.015)
    v_des = jnp.minimum(gain * speed, SLIDE_MAX_SPEED)
    obs_ = jnp.asarray(obs, jnp.float32)
    v_puck = jnp.sum((obs_[..., 14:16] + obs_[..., 20:22]) / DT * u, axis=-1, keepdims=True)
    gap = -along - PUCK_RADIUS
    in_contact = gap < SLIDE_CONTACT
    approach = jnp.clip(gap - 0.5 * SLIDE_CONTACT, 0.0, approach_speed * DT)
    push_adv = jnp.where(v_puck < v_des, push_gain * v_des * DT, 0.0)
    if trail_gap is not None:  # keep up with a gliding puck, trail_gap behind it, to push again where it stops
        trail = jnp.clip(gap - trail_gap + jnp.maximum(v_puck, 0.0) * DT, 0.0, MAX_STEP)
        approach = jnp.where(v_puck > approach_speed, trail, approach)
    advance = jnp.where(in_contact, push_adv, approach)
    target_tip = obj[..., :2] + u * (along + advance)
    follow_move = _toward(grip, jnp.concatenate([target_tip - corner, low_z], axis=-1))

    behind = obj[..., :2] - u * (PUCK_RADIUS + SLIDE_GAP) - corner
    off_xy = _norm(grip[..., :2] - behind)
    lined_up = off_xy < LINE_TOL + jnp.where(low, 0.008, 0.0)
    descend_move = _toward(grip, jnp.concatenate([behind, low_z], axis=-1))

    high = grip[..., 2:3] > safe_z - 0.02
    clear = _norm(grip[..., :2] - obj[..., :2]) > PUCK_RADIUS + SLIDE_GAP + 0.04
    travel_xy = jnp.where(high | clear, behind, grip[..., :2])
    travel_move = _toward(grip, jnp.concatenate([travel_xy, safe_z], axis=-1))

    move = jnp.where(following, follow_move, jnp.where(lined_up, descend_move, travel_move))
    move = jnp.where(dist < 0.01, 0.0, move)
    return _with_fingers(move, -1.0)


GRASP_DEPTH = 0.004  # close the fingers once the grip site is at most this far above the cube's centre
CARRY_MAX = 1.0  # largest action component while carrying


def pick_and_place(obs, goal, carry_max=CARRY_MAX):
    """Open, go above the cube, descend as deep as the fingers allow, close, then carry it to ``goal``
    (on the table or in the air)."""
    obs, grip, obj, goal = _parts(obs, goal)
    width = obs[..., 9] + obs[..., 10]  # finger opening: 0 closed, 0.1 fully open
    rel = obj - grip
    xy_off = _norm(rel[..., :2])[..., 0]
    height = -rel[..., 2]  # grip site above the cube's centre
    # Close only when deep: fingers closed on the cube's top edge hold it poorly.
    at_object = (xy_off < 0.015) & (height < GRASP_DEPTH) & (height > -0.03)
    near = (xy_off < 0.02) & (jnp.abs(height) < 0.025)
    holding = near & (width < 2 * CUBE_HALF + 0.012) & (width > 2 * CUBE_HALF - 0.02)
    is_open = width > 0.08

    # Carry: move the gripper so that the object (not the gripper) lands on the goal.
    carry = jnp.clip(_toward(grip, goal - rel), -carry_max, carry_max)
    hold = jnp.zeros_like(grip)
    # Above the object and open: descend (aiming below its centre: the table or the fingers stop the
    # gripper); not open yet: wait there.
    above = xy_off < 0.01
    descend = _toward(grip, obj - jnp.asarray([0.0, 0.0, 0.02], jnp.float32))
    hover = obj + jnp.asarray([0.0, 0.0, CLEARANCE], jnp.float32)
    # Travel at the hover height; when low and off to the side, rise before moving across.
    low = grip[..., 2] < obj[..., 2] + CLEARANCE - 0.02
    travel_xy = jnp.where((low & (xy_off < 0.06))[..., None], grip[..., :2], hover[..., :2])
    travel = _toward(grip, jnp.concatenate([travel_xy, hover[..., 2:3]], axis=-1))

    c = lambda m: m[..., None]  # noqa: E731
    move = jnp.where(
        c(holding), carry,
        jnp.where(c(at_object), hold, jnp.where(c(above), jnp.where(c(is_open), descend, hold), travel)),
    )
    fingers = jnp.where(holding | at_object, -1.0, 1.0)
    return _with_fingers(move, fingers)


def reach(obs, goal):
    """Move the gripper straight to ``goal``."""
    grip = jnp.asarray(obs, jnp.float32)[..., 0:3]
    return _with_fingers(_toward(grip, jnp.asarray(goal, jnp.float32)), 0.0)


CONTROLLERS = {"reach": reach, "push": push, "slide": slide, "pick_and_place": pick_and_place}
