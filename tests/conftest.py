"""Shared by every test: a compile cache of the run's own, and the compiled programs tests share.

Compiling one MJX program takes 10-30 s on a 2-core CPU, so each Fetch task's episodes come from one
program (``FetchEpisodes``) that every test stepping that task reuses, at one batch size and length.
"""

from __future__ import annotations

import collections
import functools
import os
import shutil
import tempfile

import jax
import jax.extend.core
import jax.numpy as jnp
import pytest

from tests import compile_cache

pytest_plugins = ("tests.hang_watchdog",)  # a test that hangs ends its worker, with every stack logged

# XLA:CPU's fusion emitters cost about a third of each compile here, and the suite is mostly
# compilation; without them the programs compute the same up to float rounding (every comparison in
# the suite is between runs made under the same flags). Known to jaxlib 0.10; other versions run as is,
# since an unknown XLA flag aborts the process.
# LLVM's optimisation level 0 compiles a Fetch episode program in 3.5 s instead of 5.6 s and runs it
# 3x slower, a trade the suite's tiny programs win.
# XLA's loop-invariant code motion takes a large share of compiling the tasks' episode programs (loops within
# loops: the episode, the substeps, the solver's), and hoists little that these short runs would miss.
CPU_COMPILE_FLAGS = (
    "--xla_cpu_use_fusion_emitters=false",
    "--xla_backend_optimization_level=0",
    "--xla_disable_hlo_passes=while-loop-invariant-code-motion",
)


def _faster_cpu_compiles() -> None:
    import jaxlib

    flags = os.environ.get("XLA_FLAGS", "")
    if jaxlib.__version__.startswith("0.10."):
        os.environ["XLA_FLAGS"] = " ".join([flags, *(f for f in CPU_COMPILE_FLAGS if f not in flags)]).strip()


def pytest_configure(config):
    _faster_cpu_compiles()  # before the first compilation; subprocesses and workers inherit it
    # Before the first compilation: the run neither reads nor writes the user's ~/.cache (JAX's
    # programs, the CLI's default --compile-cache, subprocesses' caches), and starts cold every time.
    # One directory for the whole run, made by the controlling process: a program that both xdist
    # workers (or a test's subprocesses) build compiles once.
    shared = getattr(config, "workerinput", {}).get("splid_cache_home")
    config.splid_cache_home = shared or tempfile.mkdtemp(prefix="splid-jax-tests-")
    config.splid_cache_owned = not shared
    os.environ["XDG_CACHE_HOME"] = config.splid_cache_home
    from splid_jax.cli import default_compile_cache

    os.environ["JAX_COMPILATION_CACHE_DIR"] = default_compile_cache()
    jax.config.update("jax_compilation_cache_dir", default_compile_cache())
    # Many tests (and their subprocesses) build the same small programs: keep every compile, however
    # short, so the second builder of a program loads it instead of compiling it again.
    os.environ["JAX_PERSISTENT_CACHE_MIN_COMPILE_TIME_SECS"] = "0"
    jax.config.update("jax_persistent_cache_min_compile_time_secs", 0)
    compile_cache.atomic_writes()


@pytest.hookimpl(optionalhook=True)
def pytest_configure_node(node):
    """Each xdist worker compiles into the controlling process's directory."""
    node.workerinput["splid_cache_home"] = node.config.splid_cache_home


def pytest_unconfigure(config):
    if config.splid_cache_owned:
        shutil.rmtree(config.splid_cache_home, ignore_errors=True)


# Test files that step or lower the same programs (``FetchEpisodes``'s Push programs below, and
# helpers.solver_program's and helpers.lowered_step's): one xdist work unit, so they run on one worker and each
# program compiles, or each step is traced, once (test_fused_collision steps the library-Cholesky Push program of
# test_small_cholesky and lowers the Push step of test_kernel_batch).
SHARED_PROGRAMS = {
    "tests/envs/test_fetch_tasks.py": "push-programs",
    "tests/envs/test_small_cholesky.py": "push-programs",
    "tests/splid_jax/learners/splid/test_select_mjx.py": "push-programs",
    "tests/envs/test_solver_loops.py": "push-programs",
    "tests/envs/test_fused_solver.py": "push-programs",
    "tests/envs/test_fused_collision.py": "push-programs",
    "tests/envs/test_kernel_batch.py": "push-programs",
}
# The longest units' seconds on a 2-core CPU shared with other work (a full run's --durations, summed per
# unit; one that ran beside a busy neighbour reads long). They go out first, longest first, so the last
# units handed out are short and the two workers end together (in the order of collection, a worker once
# sat idle for the last 90 s). Only the order depends on these.
UNIT_SECONDS = {
    "push-programs": 148,
    "tests/splid_jax/runtime/test_multihost.py": 43,
    "tests/splid_jax/learners/her/test_her.py": 41,
    "tests/splid_jax/test_train_processes.py": 33,
    "tests/splid_jax/learners/splid/test_trainer.py": 21,
    "tests/splid_jax/runtime/test_run_files.py": 20,
    "tests/splid_jax/learners/test_algos.py": 19,
    "tests/splid_jax/reference/test_cli.py": 18,
    "tests/splid_jax/test_train.py": 18,
    "tests/splid_jax/runtime/test_devices.py": 17,
    "tests/splid_jax/test_rollout.py": 16,
    "tests/splid_jax/runtime/test_programs.py": 15,
    "tests/splid_jax/test_figures.py": 15,
    "tests/splid_jax/test_sweep.py": 14,
    "tests/envs/test_reacher.py": 12,
    "tests/splid_jax/runtime/test_loop.py": 11,
    "tests/envs/test_slide_fingers.py": 10,
    "tests/splid_jax/learners/test_gcsl.py": 8,
    "tests/splid_jax/learners/test_es.py": 8,
    "tests/test_hang_watchdog.py": 6,
}


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_make_scheduler(config, log):
    """``--dist loadfile`` with the files of ``SHARED_PROGRAMS`` grouped into one unit each, and the
    units of ``UNIT_SECONDS`` handed out first, longest first."""
    if config.getoption("dist") != "loadfile":
        return None
    from xdist.scheduler import LoadFileScheduling

    if not hasattr(LoadFileScheduling, "_split_scope"):  # another xdist's internals: its own scheduler, unordered
        return None

    class HeaviestFirst(collections.OrderedDict):
        """The work queue: the scheduler pops its next unit from the front, and gets the longest."""

        def popitem(self, last: bool = True):
            scope = max(self, key=lambda s: UNIT_SECONDS.get(s, 0))  # ties: the first in the queue
            return scope, self.pop(scope)

    class SharedProgramScheduling(LoadFileScheduling):
        def __init__(self, config, log=None):
            super().__init__(config, log)
            self.workqueue = HeaviestFirst()  # not a reordered collection: workers take indices into theirs

        def _split_scope(self, nodeid: str) -> str:
            path = super()._split_scope(nodeid)
            return SHARED_PROGRAMS.get(path, path)

    return SharedProgramScheduling(config, log)


def _primitives(jaxpr) -> set[str]:
    names = set()
    for eqn in jaxpr.eqns:
        names.add(eqn.primitive.name)
        for sub in jax.extend.core.jaxprs_in_params(eqn.params):
            names |= _primitives(sub)
    return names


@pytest.fixture(scope="session")
def primitives():
    """``primitives(fn, *args)``: the names of the primitives in ``fn``'s jaxpr at ``args``, nested
    jaxprs included."""
    return lambda fn, *args: _primitives(jax.make_jaxpr(fn)(*args).jaxpr)


B, T = 8, 50  # envs and steps of every Fetch run (one episode)


@functools.cache
def _program(env):
    from envs.fetch import scripted

    ctl = scripted.CONTROLLERS[env.kind]

    @jax.jit
    def run(state, actions, w):
        def body(s, a):
            s = jax.vmap(env.step)(s, a + w[:, None] * ctl(s.obs, s.desired_goal))
            return s, s

        return jax.lax.scan(body, state, actions)

    return run


@functools.cache
def _reset(env):
    return jax.jit(lambda key: jax.vmap(env.reset)(jax.random.split(key, B)))


class FetchEpisodes:
    """One compiled episode program per Fetch task (any ``envs.make`` variant), always at batch ``B``
    and length ``T``: a scan of the batched step whose action is ``actions[t] + w * scripted(obs, goal)``.
    """

    B, T = B, T
    program = staticmethod(_program)

    def reset(self, env, seed=0):
        return _reset(env)(jax.random.PRNGKey(seed))

    def random_actions(self, seed=1):
        return jax.random.uniform(jax.random.PRNGKey(seed), (self.T, self.B, 4), minval=-1.0, maxval=1.0)

    def run(self, env, actions, w=0.0, state=None):
        """(start, final, trajectory): ``trajectory[t]`` is the state after step t + 1; ``w`` is one weight
        or one per env."""
        s0 = self.reset(env) if state is None else state
        w = jnp.broadcast_to(jnp.asarray(w, jnp.float32), (self.B,))
        return s0, *self.program(env)(s0, jnp.asarray(actions, jnp.float32), w)


@pytest.fixture(scope="session")
def fetch():
    return FetchEpisodes()


@functools.cache
def _scripted_or_given(env, controller):
    @jax.jit
    def run(start, actions, use_script):
        """T steps from ``start`` [N]: ``controller``'s actions, or the given ones [T, N, A]; returns the
        states after each step and the actions taken."""

        def one(s, a):
            a = jnp.where(use_script, jax.vmap(controller)(s), a)
            n = jax.vmap(env.step)(s, a)
            return n, (n, a)

        return jax.lax.scan(one, start, actions)[1]

    return run


def _fresh_starts(env, n: int, seed: int = 0):
    """``n`` starts of ``env`` from ``PRNGKey(seed)``, jitted (op by op, a vmapped reset takes seconds more)
    and traced anew at every call, so a draw outside the key would differ between two calls."""
    return jax.jit(lambda key: jax.vmap(env.reset)(jax.random.split(key, n)))(jax.random.PRNGKey(seed))


@pytest.fixture(scope="session")
def fresh_starts():
    """``fresh_starts(env, n, seed=0)``: see ``_fresh_starts``."""
    return _fresh_starts


@pytest.fixture(scope="session")
def episode_program():
    """``episode_program(env, controller)``: one compiled episode program per task and scripted
    controller (the tasks outside Fetch), shared by every test that steps it."""
    return _scripted_or_given
