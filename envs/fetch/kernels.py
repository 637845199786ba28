"""How a Fetch task's ``physics=kernels`` runs MJX: which parts of a step its options replace, on the backend
being traced for, and the options that leave the kernels out when a GPU's compiler fails on one.

The replacements are equal to MJX's own to float rounding (``tests/envs``, ``experiments/physics_equality.py``):
the small dense Cholesky solves unrolled (``cholesky``, ``envs/small_cholesky.py``), the solver's line search written
out (``solver_loops``, ``envs/solver_loops.py``), the whole solve as one program per env (``solver_loops``
``fused``, ``envs/fused_solver.py``) and the box contacts likewise (``collision``, ``envs/fused_collision.py``),
the last two Pallas kernels on a GPU. A model whose fingers are boxes against a cylinder gets MJX's missing
box-cylinder contact in the same block (``envs/box_cylinder.py``)."""

from __future__ import annotations

import jax

from envs.settings import check, check_integer

CHOLESKY = ("unrolled", "library")  # envs/small_cholesky.py, or jax.scipy.linalg's batched calls
# MJX's solver loops, its line search written out always or on a GPU only, and the whole solve as one program per
# env (envs/fused_solver.py), always or on a GPU only
SOLVER_LOOPS = ("loops", "search", "gpu-search", "fused", "gpu-fused")
COLLISION = ("mjx", "fused", "gpu-fused")  # plane-box and box-box contacts: MJX's, or envs/fused_collision.py's
KERNEL_WARPS = (1, 2, 4, 8)  # a Triton program's warps are a power of two
KERNELS = ("fused", "gpu-fused")  # the choices above that run a part of the physics as a Pallas kernel


def runs_as_kernel(choice: str, backend: str) -> bool:
    """Whether a ``solver_loops`` or ``collision`` choice runs its part as envs/fused_*.py's function on
    ``backend``: ``fused`` always, ``gpu-fused`` on a GPU only (on a CPU the functions run as XLA code: the solve
    slower than MJX's, and MJX's keeps CPU runs as they were)."""
    return choice == "fused" or (choice == "gpu-fused" and backend == "gpu")


def check_options(task) -> None:
    """Fail naming the first of ``task``'s kernel options out of its range."""
    n = task.kind
    check(task.cholesky in CHOLESKY, f"{n}.cholesky", task.cholesky, "one of " + ", ".join(CHOLESKY))
    ok = task.solver_loops in SOLVER_LOOPS
    check(ok, f"{n}.solver_loops", task.solver_loops, "one of " + ", ".join(SOLVER_LOOPS))
    check_integer(f"{n}.kernel_envs", task.kernel_envs, 0)
    ok = task.kernel_warps in KERNEL_WARPS
    check(ok, f"{n}.kernel_warps", task.kernel_warps, "one of " + ", ".join(map(str, KERNEL_WARPS)))
    check(task.collision in COLLISION, f"{n}.collision", task.collision, "one of " + ", ".join(COLLISION))


def mjx_with_kernels(task):
    """The block within which MJX steps as ``task``'s ``cholesky``, ``solver_loops`` and ``collision`` choose
    (the kernels up to ``kernel_envs`` envs, with ``kernel_warps`` warps per env), on the backend being traced
    for: the step's only way to the replaced functions. The modules that reach into MJX's private code are imported
    here, so a task on a MuJoCo whose private code moved still imports and runs stock MJX."""
    from envs import fused_collision, fused_solver, mjx_patch, small_cholesky, solver_loops

    backend = jax.default_backend()
    opts = dict(kernel=backend == "gpu", max_envs=task.kernel_envs, num_warps=task.kernel_warps)
    return mjx_patch.patched_mjx(
        cholesky=small_cholesky.UNROLLED if task.cholesky == "unrolled" else None,
        line_search=solver_loops.written_out_scan if solver_loops.writes_out(task.solver_loops, backend) else None,
        solve=fused_solver.fused(**opts) if runs_as_kernel(task.solver_loops, backend) else None,
        collide=model_contacts(
            task.mj_model, fused_collision.groups(**opts) if runs_as_kernel(task.collision, backend) else None
        ),
    )


def model_contacts(m, replaced: dict | None = None) -> dict:
    """The pair functions ({(type1, type2): group}, as ``envs/mjx_patch.py`` takes them) that model ``m`` needs
    beyond MJX's own: the box-cylinder pair MJX lacks (``envs/box_cylinder.py``), ``replaced`` (faster equivalents
    of MJX's), and, where ``m`` asks for them, the pitched pads (``hand_pitch.py``) and the table's edges
    (``table_edge.py``), which wrap whichever function collides their pairs."""
    from envs import box_cylinder
    from envs.fetch import hand_pitch, table_edge

    return table_edge.wrap(m, hand_pitch.wrap(m, {**box_cylinder.groups_for(m), **(replaced or {})}))


def kernel_fallback(task, error: BaseException) -> str | None:
    """The options that leave the physics' Triton kernels out, when a GPU's compiler failed on one (its error
    names Triton)."""
    own = (("solver_loops", "gpu-search"), ("collision", "mjx"))
    options = [f"{name}={mjx_own}" for name, mjx_own in own if getattr(task, name) in KERNELS]
    if task.physics != "kernels" or not options or "triton" not in str(error).lower():
        return None
    first = str(error).strip().splitlines()[0][:200] if str(error).strip() else type(error).__name__
    return f"{','.join(options)} (--env-options) on this GPU, whose compiler failed on a physics kernel ({first})"
