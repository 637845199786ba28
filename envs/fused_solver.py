"""MJX's Newton constraint solve as one function of an env's dense arrays, and on a GPU as one Pallas kernel.

Why: at the batches SPLID and HER step (16 to 125 envs) a Push control step launches about 2,600 GPU kernels of
about 1.7 us each, half of them the solver's Newton trips (about 38 kernels a trip; BENCHMARKS.md, "Time budget
per stage"). Here an env's whole solve (warm start, Newton trips, their line searches) is one program: on a GPU a
Pallas kernel whose grid is the envs, with its loops inside the kernel, so no trip reads a condition back to the
host; on a CPU the same function under XLA. The arithmetic is MJX's (``mujoco.mjx._src.solver.solve``) for the
models it covers (Newton, pyramidal cones, no equality or friction-loss rows: the Fetch tasks), so results agree
with MJX's to float rounding; other models keep MJX's solve.

Written for what a Triton kernel holds: no gathers or dynamic indexing (the Cholesky factor and the triangular
solves pick rows and columns with masks), shapes padded to powers of two (padded constraint rows have D = 0 and
J = 0, so they are never active; padded dofs get unit mass and no force), line-search points as tuples of scalars,
and no while loop (XLA's Triton compiler crashed on the kernel with MJX's Newton while loop in it): the Newton
trips, like the line search's, are a fixed-count loop that keeps a trip's result only where MJX's loop would
still be running.
"""

from __future__ import annotations

import jax
import jax.numpy as jnp
from mujoco.mjx._src import solver as mjx_solver
from mujoco.mjx._src import support
from mujoco.mjx._src.types import ConeType, DisableBit, SolverType

from envs import kernel_batch

MINVAL = 1e-15  # mujoco.mjMINVAL


def at_mask(x, mask):
    """The entry of ``x`` where ``mask`` holds, as a masked sum (a Triton kernel has no gather)."""
    return jnp.sum(jnp.where(mask, x, 0.0))


def _row(a, k: int):
    """a[k, :], picked with a mask."""
    return jnp.sum(jnp.where(jnp.arange(a.shape[0])[:, None] == k, a, 0.0), axis=0)


def _col(a, k: int):
    """a[:, k], picked with a mask."""
    return jnp.sum(jnp.where(jnp.arange(a.shape[1])[None, :] == k, a, 0.0), axis=1)


def chol_solve(a, b, size: int | None = None):
    """x with a x = b for a symmetric positive definite [n, n] ``a``: Cholesky-Banachiewicz, rows and columns
    picked with masks. Only the first ``size`` rows and columns are solved for; the rest of ``a`` must be the
    identity (no coupling) and of ``b`` zero, as padding leaves them."""
    n = a.shape[0]
    size = n if size is None else size
    idx = jnp.arange(n)
    low = jnp.zeros_like(a)
    for k in range(size):  # column k of L from the columns before it
        s = jnp.sum(jnp.where(idx[None, :] < k, low * _row(low, k)[None, :], 0.0), axis=1)  # sum_{m<k} L[:,m] L[k,m]
        col = _col(a, k) - s
        diag = jnp.sqrt(jnp.maximum(at_mask(col, idx == k), MINVAL))
        newcol = jnp.where(idx == k, diag, jnp.where(idx > k, col / diag, 0.0))
        low = jnp.where(idx[None, :] == k, newcol[:, None], low)
    diag = jnp.sum(jnp.where(idx[:, None] == idx[None, :], low, 0.0), axis=1)
    y = jnp.zeros_like(b)
    for k in range(size):  # forward: L y = b
        yk = (at_mask(b, idx == k) - jnp.sum(jnp.where(idx < k, _row(low, k) * y, 0.0))) / at_mask(diag, idx == k)
        y = jnp.where(idx == k, yk, y)
    x = jnp.zeros_like(b)
    for k in reversed(range(size)):  # backward: L^T x = y
        xk = (at_mask(y, idx == k) - jnp.sum(jnp.where(idx > k, _col(low, k) * x, 0.0))) / at_mask(diag, idx == k)
        x = jnp.where(idx == k, xk, x)
    return x


def _mv(a, v):
    return jnp.sum(a * v[None, :], axis=1)


def _tmv(a, v):
    return jnp.sum(a * v[:, None], axis=0)


def _dot_tn(a, b):
    """a^T b at full float32 precision (a Triton dot would otherwise round through TF32)."""
    return jax.lax.dot_general(a, b, (((0,), (0,)), ((), ())), precision=jax.lax.Precision.HIGHEST)


def newton(j, d, aref, m, qfrc_smooth, qacc_smooth, qacc_warm, trace_m, *, iterations, ls_iterations, tolerance,
           ls_tolerance, dofs: int | None = None):  # fmt: skip
    """(qacc, qfrc_constraint, efc_force) as mujoco.mjx._src.solver.solve computes them for these models.
    Line-search points are 4-tuples (alpha, cost, deriv_0, deriv_1), as MJX's _LSPoint. ``dofs``: the dofs
    before the padding, so the Hessian's factor skips the padded (decoupled) ones."""

    def gauss_of(ma, qacc):
        return 0.5 * jnp.sum((ma - qfrc_smooth) * (qacc - qacc_smooth))

    def constraint(c, prev_cost):
        jaref, ma, qacc = c["jaref"], c["ma"], c["qacc"]
        active = jaref < 0
        force = d * -jaref * active
        gauss = gauss_of(ma, qacc)
        cost = 0.5 * jnp.sum(d * jaref * jaref * active) + gauss
        return {**c, "active": active, "force": force, "qfrc": _tmv(j, force), "gauss": gauss, "cost": cost,
                "prev_cost": prev_cost}  # fmt: skip

    def fresh(qacc):
        return constraint({"qacc": qacc, "jaref": _mv(j, qacc) - aref, "ma": _mv(m, qacc)}, jnp.inf)

    def gradient(c):
        grad = c["ma"] - qfrc_smooth - c["qfrc"]
        h = m + _dot_tn(j * (d * c["active"])[:, None], j)
        h = (h + h.T) * 0.5
        return {**c, "grad": grad, "mgrad": chol_solve(h, grad, dofs)}

    def linesearch(c):
        search = c["search"]
        smag = jnp.sqrt(jnp.sum(search * search)) * trace_m
        gtol = tolerance * ls_tolerance * smag
        mv = _mv(m, search)
        jv = _mv(j, search)
        g0, g1, g2 = c["gauss"], jnp.sum(search * c["ma"]) - jnp.sum(search * qfrc_smooth), 0.5 * jnp.sum(search * mv)
        q0, q1, q2 = 0.5 * c["jaref"] * c["jaref"] * d, jv * c["jaref"] * d, 0.5 * jv * jv * d

        def pt(alpha):
            act = (c["jaref"] + alpha * jv) < 0
            t0, t1, t2 = g0 + jnp.sum(q0 * act), g1 + jnp.sum(q1 * act), g2 + jnp.sum(q2 * act)
            return alpha, alpha * alpha * t2 + alpha * t1 + t0, 2 * alpha * t2 + t1, 2 * t2 + (t2 == 0) * MINVAL

        def pick(go, a, b):
            return tuple(jnp.where(go, x, y) for x, y in zip(a, b, strict=True))

        p0 = pt(jnp.zeros((), j.dtype))
        rows_0 = jnp.maximum(p0[1] - g0, 0.0)
        rows_2 = jnp.maximum(0.5 * p0[3] - g2, 0.0)
        dmag = 2.0 * jnp.sqrt(rows_0 * rows_2) + jnp.abs(g1)
        gacc = jnp.maximum(gtol, 8 * jnp.finfo(j.dtype).eps * dmag)

        def converged(lo, hi):
            return ((jnp.abs(lo[2]) < gacc) & (lo[1] < p0[1])) | ((jnp.abs(hi[2]) < gacc) & (hi[1] < p0[1]))

        def cond(lo, hi, swap, it):
            return ~((it >= ls_iterations) | ~swap | converged(lo, hi))

        def inb(x, y):
            return ((x < y) & (y < 0)) | ((x > y) & (y > 0))

        def body(lo, hi, it):
            lo_next = pt(lo[0] - lo[2] / lo[3])
            hi_next = pt(hi[0] - hi[2] / hi[3])
            mid = pt(0.5 * (lo[0] + hi[0]))
            s1 = inb(lo[2], lo_next[2])
            lo = pick(s1, lo_next, lo)
            s2 = inb(lo[2], mid[2])
            lo = pick(s2, mid, lo)
            s3 = inb(lo[2], hi_next[2])
            lo = pick(s3, hi_next, lo)
            s4 = inb(hi[2], hi_next[2]) | ((hi[2] < 0) & (hi_next[2] > 0))
            hi = pick(s4, hi_next, hi)
            s5 = inb(hi[2], mid[2])
            hi = pick(s5, mid, hi)
            s6 = inb(hi[2], lo_next[2])
            hi = pick(s6, lo_next, hi)
            swap = s1 | s2 | s3 | s4 | s5 | s6
            costs = [jnp.where((jnp.abs(p[2]) < gacc) & (p[1] < p0[1]), p[1], jnp.inf) for p in (lo_next, hi_next, mid)]
            done = (costs[0] < jnp.inf) | (costs[1] < jnp.inf) | (costs[2] < jnp.inf)
            first = (costs[0] <= costs[1]) & (costs[0] <= costs[2])  # argmin's first minimum
            best = pick(first, lo_next, pick(costs[1] <= costs[2], hi_next, mid))
            return pick(done, best, lo), pick(done, best, hi), swap & ~done, it + 1

        lo = pt(p0[0] - p0[2] / p0[3])
        lesser = lo[2] < p0[2]
        lo, hi = pick(lesser, lo, p0), pick(lesser, p0, lo)
        swap, it = jnp.array(True), jnp.array(0, jnp.int32)

        def trip(_, carry):  # MJX's _while_loop_scan: a trip runs while the condition held after the last one
            lo, hi, swap, it, go = carry
            nlo, nhi, nswap, nit = body(lo, hi, it)
            lo, hi = pick(go, nlo, lo), pick(go, nhi, hi)
            swap, it = jnp.where(go, nswap, swap), jnp.where(go, nit, it)
            return lo, hi, swap, it, go & cond(lo, hi, swap, it)

        go = ~converged(lo, hi)  # the condition before the first trip (swap set, no trip taken): no literal in it
        lo, hi, *_ = jax.lax.fori_loop(0, ls_iterations, trip, (lo, hi, swap, it, go))
        improved = (lo[1] < p0[1]) | (hi[1] < p0[1])
        step = improved * jnp.where(lo[1] < hi[1], lo[0], hi[0])
        return {**c, "qacc": c["qacc"] + step * search, "ma": c["ma"] + step * mv, "jaref": c["jaref"] + step * jv}

    warm, smooth = fresh(qacc_warm), fresh(qacc_smooth)
    c = gradient(fresh(jnp.where(warm["cost"] < smooth["cost"], qacc_warm, qacc_smooth)))
    c = {**c, "search": -c["mgrad"], "niter": jnp.array(0, jnp.int32)}

    def ncond(c):
        improvement = (c["prev_cost"] - c["cost"]) / trace_m
        grad = jnp.sqrt(jnp.sum(c["grad"] * c["grad"])) / trace_m
        return ~((c["niter"] >= iterations) | (improvement < tolerance) | (grad < tolerance))

    def nbody(c):
        c = gradient(constraint(linesearch(c), c["cost"]))
        return {**c, "search": -c["mgrad"], "niter": c["niter"] + 1}

    def trip(_, carry):  # a Newton trip runs while MJX's while loop would; a fixed count, as Triton compiles it
        c, go = carry
        c = jax.tree.map(lambda new, old: jnp.where(go, new, old), nbody(c), c)
        return c, go & ncond(c)

    first = jnp.array(True) if iterations == 1 else ncond(c)  # MJX runs a single trip unconditionally
    c, _ = jax.lax.fori_loop(0, iterations, trip, (c, first))
    return c["qacc"], c["qfrc"], c["force"]


def _pow2(n: int) -> int:
    return 1 << max(0, (n - 1).bit_length())


def kernel_solve(j, d, aref, m, qfrc_smooth, qacc_smooth, qacc_warm, trace_m, *, interpret: bool = False,
                 num_warps: int | None = None, **opts):  # fmt: skip
    """``newton`` for one env as one Pallas kernel (``vmap`` makes the envs its grid), lowered through Triton
    (Mosaic GPU, Pallas's other GPU backend, takes no ``vmap``) with ``num_warps`` warps per env (Triton's
    default 4 when None); ``interpret`` runs the kernel's program with XLA, as on a CPU. Each enclosing ``vmap``
    is an axis of the grid, and Triton's grid has three: a sweep's members over a step's envs use two."""
    from jax.experimental import pallas as pl
    from jax.experimental.pallas import triton as pl_triton

    nefc, nv = j.shape
    p, v = _pow2(max(nefc, 16)), _pow2(max(nv, 16))
    f32 = j.dtype
    pad_r = lambda x: jnp.pad(x, (0, p - nefc))  # noqa: E731
    pad_v = lambda x: jnp.pad(x, (0, v - nv))  # noqa: E731
    jp_ = jnp.pad(j, ((0, p - nefc), (0, v - nv)))
    mp = jnp.pad(m, ((0, v - nv), (0, v - nv))) + jnp.diag((jnp.arange(v) >= nv).astype(f32))
    tr = jnp.full((v,), trace_m, f32)

    def kernel(j_ref, d_ref, aref_ref, m_ref, qfs_ref, qas_ref, qaw_ref, tr_ref, qacc_ref, qfrc_ref, force_ref):
        qacc, qfrc, force = newton(j_ref[...], d_ref[...], aref_ref[...], m_ref[...], qfs_ref[...], qas_ref[...],
                                   qaw_ref[...], jnp.max(tr_ref[...]), dofs=nv, **opts)  # fmt: skip
        qacc_ref[...] = qacc
        qfrc_ref[...] = qfrc
        force_ref[...] = force

    out = pl.pallas_call(
        kernel,
        out_shape=(jax.ShapeDtypeStruct((v,), f32), jax.ShapeDtypeStruct((v,), f32), jax.ShapeDtypeStruct((p,), f32)),
        interpret=interpret,
        compiler_params=pl_triton.CompilerParams(num_warps=num_warps),
    )(jp_, pad_r(d), pad_r(aref), mp, pad_v(qfrc_smooth), pad_v(qacc_smooth), pad_v(qacc_warm), tr)
    qacc, qfrc, force = out
    return qacc[:nv], qfrc[:nv], force[:nefc]


def covers(m, d) -> bool:
    """Whether ``newton`` is MJX's solve for this model: Newton, pyramidal cones, only inequality rows, warm
    started."""
    impl = d._impl
    friction_loss = bool(m._impl.dof_hasfrictionloss.any() or m._impl.tendon_hasfrictionloss.any())
    return (
        m.opt.solver == SolverType.NEWTON
        and m.opt.cone == ConeType.PYRAMIDAL
        and impl.ne == 0
        and impl.nf == 0
        and not friction_loss
        and impl.efc_J.shape[0] > 0
        and m.opt.iterations >= 1
        and not m.opt.disableflags & DisableBit.WARMSTART
    )


def solve(m, d, kernel: bool, num_warps: int | None = None, max_envs: int = 0):
    """``mujoco.mjx._src.solver.solve`` for the models ``covers`` takes, through ``kernel_solve`` if ``kernel``;
    with ``max_envs`` the kernel only where the innermost ``vmap`` holds at most that many envs."""
    if not covers(m, d):
        return _MJX_SOLVE(m, d)
    if kernel and max_envs:
        own = lambda x: solve(m, x, True, num_warps)  # noqa: E731
        return kernel_batch.by_batch(own, lambda x: _MJX_SOLVE(m, x), max_envs)(d)
    opts = dict(iterations=int(m.opt.iterations), ls_iterations=int(m.opt.ls_iterations),
                tolerance=float(m.opt.tolerance), ls_tolerance=float(m.opt.ls_tolerance))  # fmt: skip
    args = (d._impl.efc_J, d._impl.efc_D, d._impl.efc_aref, support.full_m(m, d), d.qfrc_smooth, d.qacc_smooth,
            d.qacc_warmstart, mjx_solver._trace_m(m, d))  # fmt: skip
    qacc, qfrc, force = kernel_solve(*args, num_warps=num_warps, **opts) if kernel else newton(*args, **opts)
    return d.tree_replace({"qfrc_constraint": qfrc, "qacc": qacc, "_impl.efc_force": force})


_MJX_SOLVE = mjx_solver.solve


def fused(kernel: bool = False, max_envs: int = 0, num_warps: int | None = None):
    """MJX's solve as ``envs/mjx_patch.py`` puts it in place of ``mujoco.mjx._src.solver.solve``: ``solve``, as a
    Pallas kernel of ``num_warps`` warps per env if ``kernel``, at batches up to ``max_envs`` if not 0."""

    def fused_solve(m, d):  # MJX's named scope takes this name: profiles file the kernel under it
        return solve(m, d, kernel, num_warps=num_warps, max_envs=max_envs)

    return fused_solve
