"""MJX's box-box and plane-box contacts (``envs/box_contacts.py``) on a GPU as one Pallas kernel per pair group, and
the collision driver's functions that run them in a step.

Why: after the constraint solve (``envs/fused_solver.py``), collision is the largest part of a Push control step on a
GPU (a fifth of its small kernels at the learners' batch sizes; experiments/NOTES.md, "What a control step
launches"), and of MJX's collision for Push the box-box pair (the finger block against the cube) is 1,111 of its 1,612
traced equations. One program per pair computes them instead. A scripted Push path follows MJX's within 1e-5 through
the finger's first contacts; after them contact amplifies rounding, as it does between MJX's own variants
(``tests/envs/test_fused_collision.py``).
"""

from __future__ import annotations

import functools

import jax
import jax.numpy as jnp

from envs import kernel_batch
from envs.base import data_with, make_data
from envs.box_contacts import box_box, box_box_soa, plane_box, plane_box_soa
from envs.fused_solver import at_mask
from envs.mjx_patch import patched_mjx


def _kernel(soa_fn, *args, interpret=False, num_warps=None):
    """``soa_fn`` on one pair's arrays (vectors [3], matrices [3, 3]) as one Pallas kernel through Triton: the inputs
    packed in one [32] vector, the outputs (4 distances, 4 points, a frame) in another; ``vmap`` makes the pairs
    and envs its grid."""
    from jax.experimental import pallas as pl
    from jax.experimental.pallas import triton as pl_triton

    shapes = [a.shape for a in args]
    flat = jnp.concatenate([a.reshape(-1) for a in args])
    packed = jnp.pad(flat, (0, 32 - flat.shape[0]))

    def kernel(in_ref, out_ref):
        x = in_ref[...]
        i32 = jnp.arange(32)
        v = [at_mask(x, i32 == k) for k in range(flat.shape[0])]
        values, at = [], 0
        for shape in shapes:
            if shape == (3,):
                values.append(tuple(v[at : at + 3]))
            else:
                values.append(tuple(tuple(v[at + 3 * r : at + 3 * r + 3]) for r in range(3)))
            at += 3 if shape == (3,) else 9
        dist, world, rows = soa_fn(*values)
        i4 = jnp.arange(4)
        out = jnp.zeros((32,), x.dtype)
        for blk, arr in enumerate((dist, *world)):
            for i in range(4):
                out = jnp.where(i32 == blk * 4 + i, at_mask(arr, i4 == i), out)
        for r in range(3):
            for c in range(3):
                out = jnp.where(i32 == 16 + 3 * r + c, rows[r][c], out)
        out_ref[...] = out

    out = pl.pallas_call(
        kernel,
        out_shape=jax.ShapeDtypeStruct((32,), packed.dtype),
        interpret=interpret,
        compiler_params=pl_triton.CompilerParams(num_warps=num_warps),
    )(packed)
    dist = out[0:4]
    pos = jnp.stack([out[4:8], out[8:12], out[12:16]], axis=-1)
    frame = out[16:25].reshape(3, 3)
    return dist, pos, jnp.broadcast_to(frame, (4, 3, 3))


def kernel_box_box(pos1, mat1, size1, pos2, mat2, size2, interpret=False, num_warps=None):
    """box_box for one pair as one Pallas kernel (vmap: the pairs and envs are its grid), through Triton."""
    return _kernel(box_box_soa, pos1, mat1, size1, pos2, mat2, size2, interpret=interpret, num_warps=num_warps)


def kernel_plane_box(plane_pos, plane_mat, box_pos, box_mat, box_size, interpret=False, num_warps=None):
    """plane_box for one pair as one Pallas kernel, through Triton."""
    return _kernel(plane_box_soa, plane_pos, plane_mat, box_pos, box_mat, box_size, interpret=interpret,
                   num_warps=num_warps)  # fmt: skip


def _box_box_group(m, d, key, geom, kernel: bool, num_warps: int | None = None):
    """The collision driver's function for the box-box group: every pair's four contacts, pairs in order."""
    g1, g2 = geom.T
    fn = functools.partial(kernel_box_box, num_warps=num_warps) if kernel else box_box
    dist, pos, frame = jax.vmap(fn)(d.geom_xpos[g1], d.geom_xmat[g1], m.geom_size[g1], d.geom_xpos[g2],
                                    d.geom_xmat[g2], m.geom_size[g2])  # fmt: skip
    return dist.reshape(-1), pos.reshape(-1, 3), frame.reshape(-1, 3, 3)


def _plane_box_group(m, d, key, geom, kernel: bool, num_warps: int | None = None):
    """The collision driver's function for the plane-box group."""
    g1, g2 = geom.T
    fn = functools.partial(kernel_plane_box, num_warps=num_warps) if kernel else plane_box
    dist, pos, frame = jax.vmap(fn)(d.geom_xpos[g1], d.geom_xmat[g1], d.geom_xpos[g2], d.geom_xmat[g2],
                                    m.geom_size[g2])  # fmt: skip
    return dist.reshape(-1), pos.reshape(-1, 3), frame.reshape(-1, 3, 3)


def _limited(group, mjx_group, max_envs: int):
    """``group`` where a step's envs are at most ``max_envs``, MJX's function for the pairs above
    (``envs/kernel_batch.py``)."""

    def collide(m, d, key, geom):
        own = lambda x, g: group(m, x, key, g)  # noqa: E731
        return kernel_batch.by_batch(own, lambda x, g: mjx_group(m, x, key, g), max_envs)(d, geom)

    return collide


def groups(kernel: bool = False, max_envs: int = 0, num_warps: int | None = None) -> dict:
    """The collision driver's functions for planes against boxes and boxes against boxes, as ``envs/mjx_patch.py``
    puts them in its table: ``plane_box`` and ``box_box`` (as Pallas kernels of ``num_warps`` warps per pair if
    ``kernel``, at batches up to ``max_envs`` if not 0, MJX's own above)."""
    from mujoco.mjx._src import collision_driver
    from mujoco.mjx._src.types import GeomType

    own = {(GeomType.PLANE, GeomType.BOX): _plane_box_group, (GeomType.BOX, GeomType.BOX): _box_box_group}
    table = {}
    for key, group in own.items():
        fn = functools.partial(group, kernel=kernel, num_warps=num_warps)
        table[key] = _limited(fn, collision_driver._COLLISION_FUNC[key], max_envs) if kernel and max_envs else fn
        table[key].ncon = 4
    return table


def contacts(task, physics, fused: bool):
    """(dist, pos, frame) of MJX's contacts for one env of a Fetch ``task`` at its ``physics`` state, collided by
    MJX's functions or, if ``fused``, by this module's: what the parity checks compare. The contacts need the
    bodies' poses alone: kinematics and collision, not the whole forward step."""
    from mujoco import mjx

    data = data_with(make_data(task.mjx_model), physics)
    with patched_mjx(collide=groups() if fused else None):
        c = mjx.collision(task.mjx_model, mjx.kinematics(task.mjx_model, data))._impl.contact
    return c.dist, c.pos, c.frame
