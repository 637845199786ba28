"""MJX's constraint rows for frictional contacts (``mujoco.mjx._src.constraint.make_constraint``) as one program
per env, and on a GPU as one Pallas kernel.

Why: with the solve and the box contacts as kernels, ``make_constraint`` is among the largest parts left of a Push
control step on a GPU (200 small kernels, 0.32 ms at 16 envs; BENCHMARKS.md, "Time budget per stage"). The rows
are MJX's for the models this covers (pyramidal cones, contacts of dimension 3 and 4, no equality, friction-loss
or limit rows: Push and Slide): for each contact, its bodies' point Jacobians (the dofs on each body's path to the
world, which the model fixes), projected on the contact frame and combined into the pyramid's edges; then each
row's stiffness, damping and impedance, its regulariser and reference acceleration. Contacts come in MJX's order
(dimension 3, then 4), so the rows are where MJX puts them, and equal to float rounding.

Written for what a Triton kernel holds: the contacts' fields packed in one [contacts, 32] table and each contact's
row picked with a mask, vectors over the dofs padded to 16, no gathers (a contact's bodies picked by masks from its
geoms), no constant arrays (the model's numbers enter as Python floats), no concatenation (rows placed by masks).
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import operator
import types

import jax
import jax.numpy as jnp
import mujoco
import numpy as np
from mujoco.mjx._src import constraint as mjx_constraint

from envs import kernel_batch
from envs.fused_solver import at_mask, col_at, pow2, row_at
from envs.small_cholesky import TRACE_LOCK

# the contact table's columns: dist, includemargin, pos (3), frame (9), friction (3), solref (2), solimp (5), geom (2)
_DIST, _MARGIN, _POS, _FRAME, _FRICTION, _SOLREF, _SOLIMP, _GEOM = 0, 1, 2, 5, 14, 17, 19, 24
_WIDTH = 32


@dataclasses.dataclass(frozen=True)
class Layout:
    """What the model fixes about the rows: each contact's dimension (MJX's order), the geoms' bodies, each body's
    dofs (its path to the world), the bodies' roots and translational inverse weights, the solver's constants."""

    dims: tuple[int, ...]
    nv: int
    geom_body: tuple[int, ...]
    body_dofs: tuple[tuple[int, ...], ...]
    body_root: tuple[int, ...]
    invweight: tuple[float, ...]
    impratio: float
    timestep: float
    disableflags: int

    @property
    def nefc(self) -> int:
        return sum(2 * (d - 1) for d in self.dims)


def layout(m, d) -> Layout | None:
    """The rows' layout for this model and data, or None where ``make_constraint`` makes other rows than this
    module's (other cones or contact dimensions, equality, friction-loss, limit or tendon rows)."""
    from mujoco.mjx._src.types import ConeType, DisableBit

    impl = d._impl
    dims = tuple(int(x) for x in np.asarray(impl.contact.dim))
    limited = bool(np.any(m.jnt_limited)) or bool(np.any(getattr(m, "tendon_limited", ())))
    friction_loss = bool(m._impl.dof_hasfrictionloss.any() or m._impl.tendon_hasfrictionloss.any())
    order = sorted(dims, key=lambda x: (3, 4).index(x) if x in (3, 4) else 9)
    if (
        m.opt.cone != ConeType.PYRAMIDAL
        or m.opt.disableflags & DisableBit.CONSTRAINT
        or not dims
        or any(x not in (3, 4) for x in dims)
        or tuple(order) != dims
        or m.neq
        or limited
        or friction_loss
        or impl.efc_J.shape[0] != sum(2 * (x - 1) for x in dims)
    ):
        return None
    parent, dof_body = np.asarray(m.body_parentid), np.asarray(m.dof_bodyid)
    body_dofs = []
    for b in range(m.nbody):
        path, x = set(), b
        while x > 0:
            path.add(x)
            x = int(parent[x])
        body_dofs.append(tuple(int(i) for i in np.nonzero(np.isin(dof_body, list(path)))[0]))
    return Layout(
        dims=dims,
        nv=int(m.nv),
        geom_body=tuple(int(x) for x in np.asarray(m.geom_bodyid)),
        body_dofs=tuple(body_dofs),
        body_root=tuple(int(x) for x in np.asarray(m.body_rootid)),
        invweight=tuple(float(x) for x in np.asarray(m.body_invweight0)[:, 0]),
        impratio=float(m.opt.impratio),
        timestep=float(m.opt.timestep),
        disableflags=int(m.opt.disableflags),
    )


def contact_table(contact, rows: int | None = None):
    """The contacts' fields as one [rows, 32] table (rows padded with zeros), the kernel's input."""
    c = contact
    n = c.dist.shape[0]
    cols = [c.dist[:, None], c.includemargin[:, None], c.pos, c.frame.reshape(n, 9), c.friction[:, :3], c.solref,
            c.solimp, c.geom.astype(c.dist.dtype)]  # fmt: skip
    table = jnp.concatenate(cols, axis=1)
    rows = n if rows is None else rows
    return jnp.pad(table, ((0, rows - n), (0, _WIDTH - table.shape[1])))


def rows(lay: Layout, table, cdof, com, qvel):
    """MJX's constraint rows for one env: (J [P, V], D, aref, pos, margin [P]) with P and V the rows and dofs
    padded to powers of two. ``table`` is ``contact_table``'s, ``cdof`` [V, 8] and ``com`` (the bodies' subtree
    centres of mass) [B, 4] padded, ``qvel`` [V]."""
    nrows, nvp = pow2(max(lay.nefc, 16)), cdof.shape[0]
    dof, row_idx = jnp.arange(nvp), jnp.arange(nrows)
    cd = [col_at(cdof, k) for k in range(6)]  # cdof's columns over the dofs: rotation (0-2), translation (3-5)
    bodies = range(len(lay.body_dofs))
    masks = [
        _total((dof == i).astype(cdof.dtype) for i in dofs) if dofs else jnp.zeros_like(qvel) for dofs in lay.body_dofs
    ]
    roots = [[at_mask(row_at(com, lay.body_root[b]), jnp.arange(com.shape[1]) == k) for k in range(3)] for b in bodies]

    def pick(values, body):  # values[body] for a traced body index, by masks
        return _total((body == b).astype(cdof.dtype) * v for b, v in enumerate(values))

    def jac(point, body):  # point Jacobian columns over the dofs: translation (3) and rotation (3)
        mask = pick(masks, body)
        off = [point[k] - pick([r[k] for r in roots], body) for k in range(3)]
        cross = (cd[1] * off[2] - cd[2] * off[1], cd[2] * off[0] - cd[0] * off[2], cd[0] * off[1] - cd[1] * off[0])
        return [mask * (cd[3 + k] + cross[k]) for k in range(3)], [mask * cd[k] for k in range(3)]

    J = jnp.zeros((nrows, nvp), cdof.dtype)
    D = aref = pos_out = margin_out = jnp.zeros((nrows,), cdof.dtype)
    # MJX's stiffness, damping and impedance read the model's timestep and flags: here as Python numbers, which a
    # kernel holds (it captures no arrays)
    scalars = types.SimpleNamespace(opt=types.SimpleNamespace(timestep=lay.timestep, disableflags=lay.disableflags))
    r = 0
    width = jnp.arange(_WIDTH)
    for c, dim in enumerate(lay.dims):
        rec = row_at(table, c)
        f = [at_mask(rec, width == k) for k in range(_GEOM + 2)]
        frame = [f[_FRAME + 3 * i : _FRAME + 3 * i + 3] for i in range(3)]
        point = f[_POS : _POS + 3]
        body1 = _body(lay, f[_GEOM])
        body2 = _body(lay, f[_GEOM + 1])
        p1, r1 = jac(point, body1)
        p2, r2 = jac(point, body2)
        diff = [_total(frame[i][k] * (p2[k] - p1[k]) for k in range(3)) for i in range(3)]
        if dim > 3:
            diff.append(_total(frame[0][k] * (r2[k] - r1[k]) for k in range(3)))
        fri = f[_FRICTION : _FRICTION + dim - 1]
        pos = f[_DIST] - f[_MARGIN]
        active = pos < 0
        inv = pick(lay.invweight, body1) + pick(lay.invweight, body2)
        inv = (inv + fri[0] * fri[0] * inv) * 2 * fri[0] * fri[0] / lay.impratio
        k_, b_, imp = mjx_constraint._kbi(scalars, f[_SOLREF : _SOLREF + 2], f[_SOLIMP : _SOLIMP + 5], pos)
        reg = jnp.maximum(inv * (1 - imp) / imp, mujoco.mjMINVAL)
        pos_aref = jnp.where(active, pos, 0.0)
        for e in range(dim - 1):
            for sign in (1.0, -1.0):
                j = jnp.where(active, diff[0] + diff[1 + e] * (sign * fri[e]), 0.0)
                J = jnp.where(row_idx[:, None] == r, j[None, :], J)
                a = -b_ * jnp.sum(j * qvel) - k_ * imp * pos_aref
                D, aref = jnp.where(row_idx == r, 1 / reg, D), jnp.where(row_idx == r, a, aref)
                pos_out = jnp.where(row_idx == r, pos_aref + f[_MARGIN], pos_out)
                margin_out = jnp.where(row_idx == r, f[_MARGIN], margin_out)
                r += 1
    return J, D, aref, pos_out, margin_out


def _total(terms):
    """The terms' sum without Python's integer start (Triton adds no integer to a float)."""
    return functools.reduce(operator.add, terms)


def _body(lay: Layout, geom):
    """The body of a geom index held as a float, by masks (as products: the select form failed to lower for Triton)."""
    return _total((geom == g).astype(geom.dtype) * float(b) for g, b in enumerate(lay.geom_body))


def make_constraint(m, d, kernel: bool = False, interpret: bool = False, max_envs: int = 0):
    """``make_constraint`` for the models ``layout`` takes (MJX's own for others), its rows computed by ``rows``,
    through one Pallas kernel if ``kernel`` (at batches up to ``max_envs`` if not 0, MJX's above)."""
    lay = layout(m, d)
    if lay is None:
        return _MJX_MAKE_CONSTRAINT(m, d)
    if kernel and max_envs:
        own = lambda x: make_constraint(m, x, True, interpret)  # noqa: E731
        return kernel_batch.by_batch(own, lambda x: _MJX_MAKE_CONSTRAINT(m, x), max_envs)(d)
    impl = d._impl
    ncon, nvp = len(lay.dims), pow2(max(lay.nv, 16))
    table = contact_table(impl.contact, pow2(max(ncon, 16)))
    cdof = jnp.pad(d.cdof, ((0, nvp - lay.nv), (0, 2)))
    nb = d.subtree_com.shape[0]
    com = jnp.pad(d.subtree_com, ((0, pow2(max(nb, 2)) - nb), (0, 1)))
    qvel = jnp.pad(d.qvel, (0, nvp - lay.nv))
    args = (table, cdof, com, qvel)
    out = _kernel_rows(lay, *args, interpret=interpret) if kernel else rows(lay, *args)
    J, D, aref, pos, margin = out
    n = lay.nefc
    return d.tree_replace(
        {
            "_impl.efc_J": J[:n, : lay.nv],
            "_impl.efc_D": D[:n],
            "_impl.efc_aref": aref[:n],
            "_impl.efc_pos": pos[:n],
            "_impl.efc_margin": margin[:n],
            "_impl.efc_frictionloss": jnp.zeros_like(D[:n]),
        }
    )


def _kernel_rows(lay: Layout, table, cdof, com, qvel, interpret: bool = False):
    """``rows`` as one Pallas kernel through Triton (``vmap`` makes the envs its grid)."""
    from jax.experimental import pallas as pl
    from jax.experimental.pallas import triton as pl_triton

    nrows, nvp = pow2(max(lay.nefc, 16)), cdof.shape[0]

    def kernel(t_ref, c_ref, m_ref, q_ref, j_ref, d_ref, a_ref, p_ref, g_ref):
        outs = rows(lay, t_ref[...], c_ref[...], m_ref[...], q_ref[...])
        for ref, value in zip((j_ref, d_ref, a_ref, p_ref, g_ref), outs, strict=True):
            ref[...] = value

    f32 = cdof.dtype
    shapes = [jax.ShapeDtypeStruct((nrows, nvp), f32)] + [jax.ShapeDtypeStruct((nrows,), f32)] * 4
    return pl.pallas_call(kernel, out_shape=shapes, interpret=interpret,
                          compiler_params=pl_triton.CompilerParams())(table, cdof, com, qvel)  # fmt: skip


_MJX_MAKE_CONSTRAINT = mjx_constraint.make_constraint


@contextlib.contextmanager
def fused_in_mjx(enabled: bool = True, kernel: bool = False, interpret: bool = False, max_envs: int = 0):
    """Within the block, MJX's forward dynamics make their constraint rows through ``make_constraint`` (as a Pallas
    kernel if ``kernel``, at batches up to ``max_envs`` if not 0). MJX looks ``constraint.make_constraint`` up
    when its code runs: at trace time under ``jit``."""
    if not enabled:
        yield
        return

    def rows_in_scope(m, d):  # under MJX's stage name, where profiles look for it
        with jax.named_scope("make_constraint"):
            return make_constraint(m, d, kernel, interpret, max_envs)

    with TRACE_LOCK:
        mjx_constraint.make_constraint = rows_in_scope
        try:
            yield
        finally:
            mjx_constraint.make_constraint = _MJX_MAKE_CONSTRAINT
