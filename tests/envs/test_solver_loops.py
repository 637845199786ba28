"""MJX's solver with its line search written out: the loop's arithmetic to float rounding, and the Newton
loop left as it is."""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import envs
from envs import solver_loops
from tests.helpers import needs_kernels, solver_path, solver_program


def _loop_counts(text: str, episode_scans: int = 0) -> dict[str, int]:
    """How many while and scan loops ``text`` (a jaxpr) holds, less the episode's own ``episode_scans``."""
    return {"while[": text.count("while["), "scan[": text.count("scan[") - episode_scans}


def _loop_primitives(choice: str | None = None) -> set[str]:
    """The loop primitives of the step with the solver's loops as ``choice`` has them: read from the
    episode program that runs (less its episode scan) where the tests run that choice, else from a
    trace of the lone step."""
    if choice in ("loops", "search"):
        counts = _loop_counts(str(solver_program(choice)[0].jaxpr), episode_scans=1)
    else:
        options = {} if choice is None else {"solver_loops": choice}
        env = envs.make("push", substeps=1, iterations=2, ls_iterations=2, cholesky="library", **options)
        state = jax.eval_shape(env.reset, jax.random.PRNGKey(0))  # its shapes are all a trace needs
        counts = _loop_counts(str(jax.make_jaxpr(env.step)(state, jnp.zeros(4))))
    return {p for p, n in counts.items() if n > 0}


@needs_kernels
def test_the_cpu_steps_through_the_solvers_own_loops_by_default():
    assert _loop_primitives("loops") == {"while[", "scan["}  # Newton, its line search, the substeps
    assert _loop_primitives() == {"while[", "scan["}  # the default, gpu-search: the loops on the CPU


@needs_kernels
def test_written_out_line_search_keeps_the_newton_loop_alone():
    counts = _loop_counts(str(solver_program("search")[0].jaxpr), episode_scans=1)
    assert counts == {"while[": 1, "scan[": 1}  # the Newton loop and the substeps'


def test_gpu_choices_write_the_line_search_out_on_a_gpu_only():
    assert [solver_loops.writes_out("search", b) for b in ("gpu", "cpu")] == [True, True]
    assert [solver_loops.writes_out("loops", b) for b in ("gpu", "cpu")] == [False, False]
    for choice in ("gpu-search", "gpu-fused"):  # gpu-fused: where MJX's solve still runs on a GPU
        assert [solver_loops.writes_out(choice, b) for b in ("gpu", "cpu", "tpu")] == [True, False, False]


def test_written_out_line_search_follows_the_loops_path():
    loops, written = solver_path("loops"), solver_path("search")
    assert np.isfinite(written).all()
    np.testing.assert_allclose(written, loops, atol=1e-5)


def test_the_written_out_line_search_stops_where_the_loop_would():
    # trips after the condition fails leave the value as the loop left it
    n = jax.jit(lambda x: solver_loops.written_out_scan(lambda i: i < 3, lambda i: i + 1, x, 10))(jnp.int32(0))
    assert int(n) == 3


def test_settings_record_the_written_out_solver_only_when_chosen():
    # a run recorded before the option existed matches a task at its default
    assert "solver_loops" not in envs.make("push").settings()
    assert envs.make("push", solver_loops="loops").settings()["solver_loops"] == "loops"
    assert envs.make("push", solver_loops="search").settings()["solver_loops"] == "search"
    with pytest.raises(ValueError, match="solver_loops"):  # the written-out Newton loop was retired
        envs.make("push", solver_loops="unrolled")
