"""MJX's Newton solve as one program per env: MJX's arithmetic to float rounding, its Pallas kernel the same
function, and MJX's own solve for models it does not cover."""

from __future__ import annotations

import functools

import jax
import jax.numpy as jnp
import numpy as np

import envs
from envs import fused_solver
from envs.fetch.kernels import runs_as_kernel
from tests.helpers import needs_kernels, solver_path, triton_calls_for_gpu


def test_fused_solve_follows_mjx_path():
    fused, loops = solver_path("fused"), solver_path("loops")  # two trips: a miscounted one parts them
    assert np.isfinite(fused).all()
    np.testing.assert_allclose(fused, loops, atol=1e-5)


def _problem(seed, nefc=40, nv=9):
    """A random solve with a third of the rows pushing against their constraint (negative aref), drawn by
    numpy (no program compiled for it)."""
    rng = np.random.default_rng(seed)
    j = rng.normal(size=(nefc, nv))
    a = rng.normal(size=(nv, nv))
    m = a @ a.T + nv * np.eye(nv)
    d = rng.uniform(0.1, 10.0, nefc)
    aref = rng.normal(size=nefc) - 0.3
    qfrc_smooth, qacc_smooth = rng.normal(size=(2, nv))
    qacc_warm = qacc_smooth + 0.1 * rng.normal(size=nv)
    return tuple(np.float32(x) for x in (j, d, aref, m, qfrc_smooth, qacc_smooth, qacc_warm, np.trace(m)))


def _problems(n, nefc=40):
    """``n`` of ``_problem``'s, stacked as a batch of envs."""
    return tuple(np.stack(x) for x in zip(*(_problem(seed, nefc) for seed in range(n)), strict=True))


def test_kernel_is_the_function_for_a_batch_of_envs():
    opts = dict(iterations=4, ls_iterations=4, tolerance=1e-8, ls_tolerance=0.01)
    problems = _problems(3)
    plain = jax.jit(jax.vmap(functools.partial(fused_solver.newton, **opts)))(*problems)
    kernel = jax.jit(jax.vmap(functools.partial(fused_solver.kernel_solve, interpret=True, **opts)))(*problems)
    assert float(jnp.abs(plain[2]).max()) > 0  # some rows push
    for got, want in zip(kernel, plain, strict=True):
        np.testing.assert_allclose(got, want, rtol=1e-5, atol=1e-5)


def test_masked_cholesky_solves_the_system():
    j, _, _, m, b, *_ = _problem(2)
    np.testing.assert_allclose(fused_solver.chol_solve(m, b), jnp.linalg.solve(m, b), rtol=1e-5, atol=1e-6)


def test_mjx_solve_kept_for_models_not_covered():
    from mujoco import mjx
    from mujoco.mjx._src.types import ConeType, DisableBit

    model = envs.make("push").mjx_model
    data = mjx.make_data(model)  # the constraint rows' shapes are all ``covers`` reads
    assert fused_solver.covers(model, data)
    elliptic = model.replace(opt=model.opt.replace(cone=ConeType.ELLIPTIC))
    assert not fused_solver.covers(elliptic, data)
    cold = model.replace(opt=model.opt.replace(disableflags=model.opt.disableflags | DisableBit.WARMSTART))
    assert not fused_solver.covers(cold, data)


def test_kernel_lowers_through_triton_as_one_call_for_a_batch():
    # lowered for a GPU on this host (Pallas's Triton lowering needs no device): a construct Triton cannot
    # hold fails here, not first on a GPU machine
    opts = dict(iterations=4, ls_iterations=4, tolerance=1e-8, ls_tolerance=0.01)
    problems = _problems(8, nefc=56)
    solve = jax.vmap(functools.partial(fused_solver.kernel_solve, **opts))
    text = jax.jit(solve).trace(*problems).lower(lowering_platforms=("cuda",)).as_text()
    assert text.count("xla.gpu.triton") == 1 and "grid_x = 8" in text


def _primitives(jaxpr) -> set[str]:
    """Every primitive in ``jaxpr`` and the jaxprs inside its equations (loop bodies, branches)."""
    names = set()
    for eqn in jaxpr.eqns:
        names.add(eqn.primitive.name)
        for value in eqn.params.values():
            for sub in value if isinstance(value, tuple | list) else (value,):
                inner = getattr(sub, "jaxpr", sub)
                if hasattr(inner, "eqns"):
                    names |= _primitives(inner)
    return names


def test_solve_has_no_while_loop():
    # XLA's Triton compiler on a GPU crashed (segmentation fault) on kernels holding a while loop; the
    # Newton trips and line searches are fixed-count loops with their conditions as masks
    opts = dict(iterations=4, ls_iterations=4, tolerance=1e-8, ls_tolerance=0.01)
    jaxpr = jax.make_jaxpr(functools.partial(fused_solver.newton, **opts))(*_problem(3))
    names = _primitives(jaxpr.jaxpr)
    assert "scan" in names and "while" not in names


@needs_kernels
def test_push_default_solves_through_the_kernel_on_a_gpu_only():
    # (none on this CPU: test_fused_collision's count for the default step, which holds the solve's kernel too)
    assert triton_calls_for_gpu(envs.make("push", substeps=1, collision="mjx")) == 1
    assert [runs_as_kernel("gpu-fused", b) for b in ("gpu", "cpu")] == [True, False]
    assert runs_as_kernel("fused", "cpu") and not runs_as_kernel("gpu-search", "gpu")


def test_a_kernel_compile_failure_names_the_options_that_avoid_it():
    error = RuntimeError("INTERNAL: Triton compilation failed\nmore")
    hint = envs.make("push", collision="mjx").kernel_fallback(error)
    assert "solver_loops=gpu-search" in hint and "collision" not in hint
    assert "Triton compilation failed" in hint and "more" not in hint
    both = envs.make("push").kernel_fallback(error)
    assert "solver_loops=gpu-search,collision=mjx" in both
    assert envs.make("push").kernel_fallback(RuntimeError("RESOURCE_EXHAUSTED: out of memory")) is None
    assert envs.make("push", solver_loops="gpu-search", collision="mjx").kernel_fallback(error) is None
    assert envs.make("point").kernel_fallback(error) is None
