"""Slide's closed fingers as MJCF: what strikes and presses the puck (``models.mjcf`` for ``kind="slide"``).

- ``"box"`` (the former default): a block drawn for the closed fingers that meets the puck through four 4 mm
  spheres at its corners, since stock MJX collides a cylinder with a sphere but not with a box. A gripper pressed
  on the puck rests on the spheres, and learnt policies ride the puck's top face where the reference's slip off
  (experiments/NOTES.md, "Why learnt Slide policies fail in FetchSlide-v4").
- ``"pads"`` (Slide's default): the reference's two finger pads, boxes of its size at its closed fingers' place
  about the grip site, with its finger-puck contact (condim 4, friction, margin, solref and solimp as MuJoCo mixes
  the two geoms'). MJX collides them with the puck through ``envs/box_cylinder.py``, which a step must register
  (``box_cylinder.groups``).
  The reference's fingers also touch its table (``finger_table=1``), and its arm, pulled by a mocap weld, presses
  them into the puck far harder than the PD drive: with ``drive=weld`` and ``gripper_mass=22`` (its arm's effective
  mass along z at the grip site) they sink as deep as there and drag the puck as fast
  (``experiments/reference/results/slide-pads.md``, which also says what still differs).
"""

from __future__ import annotations

FINGERS = ("box", "pads")
TIP_XY = 0.0155  # "box": fingertip corner centres at (+-, +-) this from the grip site: scripted.FINGER_HALF_XY
TIP_RADIUS = 0.004
TIP_FRICTION = "1 1 0.05 0.01 0.01"  # the reference finger-puck pair: friction 1, torsional 0.05, condim 4
# "pads": a reference finger geom's half sizes (x, y, z in the world at the Slide start; its long axis is
# vertical) and the centres of the right and left ones about the grip site, read off FetchSlide-v4 where its pads are
# when they strike (at reset its left finger is still open, 1.5 mm further out: NOTES, "The strike, traced")
PAD_HALF = (0.0135, 0.007, 0.0385)
PAD_CENTERS = ((-0.0002, 0.008, 0.02), (-0.0002, -0.008, 0.02))
# the pad-puck pair as MuJoCo mixes a pad (condim 4, friction 1 0.05 0.01, margin 0.001, solref 0.01 1, solimp
# 0.99 0.99 0.01) with the puck (condim 3, friction 0.1 0.005 0.0001, the default solref and solimp)
PAD_PUCK_CONTACT = ('condim="4" friction="1 1 0.05 0.01 0.01" margin="0.001" solref="0.015 1" '
                    'solimp="0.945 0.97 0.0055 0.5 2"')  # fmt: skip


def _fmt(*xs: float) -> str:
    return " ".join(f"{x:.6g}" for x in xs)


def mjcf(finger: str, below: float, finger_table: float, visual: str) -> tuple[str, str, tuple[str, ...]]:
    """(the gripper body's finger geoms, the finger-puck contact pairs, the names of the geoms that may touch the
    table) for ``finger``; ``below``: how far the fingertips reach below the grip site ("box"), ``finger_table``
    whether they touch the table, ``visual`` the geoms' shared attributes."""
    if finger == "pads":
        (hx, hy, hz), names = PAD_HALF, ("pad_r", "pad_l")
        geoms = "".join(
            f"""
      <geom name="{n}" type="box" size="{_fmt(hx, hy, hz)}" pos="{_fmt(*c)}" mass="0.001" {visual}/>"""
            for n, c in zip(names, PAD_CENTERS, strict=True)
        )
        pairs = "".join(f"""
    <pair geom1="{n}" geom2="object" {PAD_PUCK_CONTACT}/>""" for n in names)  # fmt: skip
        return geoms, pairs, names
    # Closed fingers drawn as a block; they strike the puck with four round corner tips. With a finger-table
    # contact the block and the tips reach the reference's fingertips' depth, the tips' bottoms level with
    # the block's (without it, the tips' centres sit at the grip site, where they were fitted to the strike).
    c, r = TIP_XY, TIP_RADIUS
    finger_z = 0.03 - below  # block half-height 0.03, bottom ``below`` the grip site
    tips = [(f"tip_{i}", sx * c, sy * c) for i, (sx, sy) in enumerate([(1, 1), (1, -1), (-1, 1), (-1, -1)])]
    block_z, tip_z = (finger_z, r - below) if finger_table > 0 else (finger_z + r, 0.0)
    geoms = f"""
      <geom name="fingers" type="box" size="{_fmt(c, c)} 0.03" pos="0 0 {block_z:.6g}" mass="0.001" {visual}/>"""
    geoms += "".join(f"""
      <geom name="{n}" type="sphere" size="{r:.6g}" pos="{_fmt(x, y, tip_z)}" mass="0.001" {visual}/>"""
                     for n, x, y in tips)  # fmt: skip
    pairs = "".join(f"""
    <pair geom1="{n}" geom2="object" condim="4" friction="{TIP_FRICTION}"/>""" for n, _, _ in tips)  # fmt: skip
    return geoms, pairs, ("fingers",)
