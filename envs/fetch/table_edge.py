"""Slide's table top ending where the reference's table does (``table="edged"``).

MJX collides a cylinder with a plane but not with a box, so Slide's table top is a plane, and a plane has no edge:
a puck struck or carried past FetchSlide-v4's table (x 0.695 to 1.945, y 0.30 to 1.20) slides on in the air, where
the reference's falls to the floor (experiments/NOTES.md, "Slide's table edge"). Here each of the
puck-table contact points (MJX's plane-cylinder gives three on the puck's rim) that lies outside the table's x-y
extent moves to the table's edge, its depth that of the puck's bottom face there: a puck whose centre is over the
table keeps its support up to the edge, one half over it tips about the edge, and a point that no longer lies
under the puck's bottom face (the puck past the edge) or, on a puck over the edge, lies deep under the top
(``BELOW_TOP``) is dropped, so the puck falls to the floor; a puck pressed deep well inside keeps its support.
Carried by the model as a custom numeric (x0, x1, y0, y1), so a model's own contacts know it (``wrap``).
"""

from __future__ import annotations

import jax.numpy as jnp
import numpy as np

NUMERIC = "table_edge"
APART = 1.0  # m: a dropped contact's distance, far beyond any margin, so the solver leaves it inactive
# m: a point this far under the top is the puck's rim fallen past the edge, which the box's side face would meet,
# not its top: held by the top it would be thrown up
BELOW_TOP = 0.005


def extent_of(m) -> tuple[float, float, float, float] | None:
    """The model's table extent (x0, x1, y0, y1) from its ``table_edge`` numeric (an MjModel), None without one."""
    names = [m.numeric(i).name for i in range(m.nnumeric)]
    return tuple(float(x) for x in np.asarray(m.numeric(NUMERIC).data)) if NUMERIC in names else None


def edged(group, table: int, extent: tuple[float, float, float, float]):
    """The collision driver's plane-cylinder ``group`` with the contact points of geom ``table`` kept within
    ``extent``: moved onto its edge, or dropped (pushed ``APART``)."""
    lo, hi = jnp.array(extent[0::2]), jnp.array(extent[1::2])

    def on_the_table(m, d, key, geom):
        dist, pos, frame = group(m, d, key, geom)
        pairs = jnp.repeat(geom, group.ncon, axis=0)
        with_table = jnp.any(pairs == table, axis=1)
        puck = jnp.where(pairs[:, 0] == table, pairs[:, 1], pairs[:, 0])
        axis = d.geom_xmat[puck][:, :, 2]
        axis = axis * jnp.where(axis[:, 2:] < 0, -1.0, 1.0)  # up
        edge = jnp.clip(pos[:, :2], lo, hi)
        shift = edge - pos[:, :2]
        deeper = -jnp.sum(axis[:, :2] * shift, axis=1) / jnp.maximum(axis[:, 2], 0.1)  # the bottom face's rise there
        bottom = d.geom_xpos[puck] - axis * m.geom_size[puck, 1:2]  # the bottom face's centre
        moved_far = jnp.linalg.norm(edge - bottom[:, :2], axis=1) > m.geom_size[puck, 0] + 1e-4
        past = jnp.any(shift != 0, axis=1)  # the point lies beyond the table's extent
        under = ~(past & moved_far)
        # over the edge: a pair with a point past the edge (a puck pressed deep well inside keeps its support)
        overhang = jnp.repeat(jnp.any(past.reshape(-1, group.ncon), axis=1), group.ncon)
        moved = jnp.concatenate([edge, pos[:, 2:] + deeper[:, None] / 2], axis=1)
        depth = dist + deeper
        kept = under & ((depth > -BELOW_TOP) | ~overhang)
        dist = jnp.where(with_table, jnp.where(kept, depth, APART), dist)
        return dist, jnp.where(with_table[:, None], moved, pos), frame

    on_the_table.ncon = group.ncon
    return on_the_table


def wrap(m, collide: dict) -> dict:
    """``collide`` ({(type1, type2): group}, as ``envs/mjx_patch.py`` takes it) with the puck's plane-cylinder
    contacts ending at the table's edges where model ``m`` asks for it."""
    extent = extent_of(m)
    if extent is None:
        return collide
    from mujoco.mjx._src import collision_driver
    from mujoco.mjx._src.types import GeomType

    key = (GeomType.PLANE, GeomType.CYLINDER)
    group = collide.get(key, collision_driver._COLLISION_FUNC[key])
    return {**collide, key: edged(group, m.geom("table").id, extent)}
