"""Whether a run's program fits the device, checked before any state is allocated: a run that
cannot fit is refused with its estimate (exit code 2), not left to fail mid-run."""

from __future__ import annotations

import os

import numpy as np

import envs
from splid_jax.common.errors import InvalidConfig
from splid_jax.config import TrainConfig
from splid_jax.learners import registry


class DoesNotFit(InvalidConfig):
    """The run's arrays cannot fit the device's memory."""

    def __init__(self, message: str):
        ValueError.__init__(self, message)
        self.field, self.value, self.allowed = "num_envs", None, message


def nbytes(aval) -> int:
    shape = getattr(aval, "shape", None)
    if shape is None:
        return 0
    try:
        itemsize = np.dtype(aval.dtype).itemsize
    except TypeError:  # extended dtypes (typed PRNG keys)
        itemsize = 8
    return int(np.prod(shape, dtype=np.int64)) * itemsize


def subjaxprs(value):
    if hasattr(value, "eqns"):
        yield value
    elif hasattr(value, "jaxpr") and hasattr(value.jaxpr, "eqns"):
        yield value.jaxpr
    elif isinstance(value, tuple | list):
        for v in value:
            yield from subjaxprs(v)


def largest_value(jaxpr) -> int:
    """Bytes of the largest set of values one operation of ``jaxpr`` (nested ones included) makes:
    a lower bound of the memory the program needs beside its inputs and outputs."""
    best = 0
    for eqn in jaxpr.eqns:
        best = max(best, sum(nbytes(v.aval) for v in eqn.outvars))
        for value in eqn.params.values():
            for sub in subjaxprs(value):
                best = max(best, largest_value(sub))
    return best


def device_memory(device) -> tuple[int, str]:
    """Bytes the device may hold, and where the figure comes from."""
    stats = device.memory_stats() if hasattr(device, "memory_stats") else None
    if stats and stats.get("bytes_limit"):
        return int(stats["bytes_limit"]), f"{device.device_kind} memory"
    return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"), "host RAM"


def gigabytes(n: float) -> str:
    return f"{n / 1e9:.1f} GB" if n >= 1e8 else f"{n / 1e6:.1f} MB"


def sizes(cfg: TrainConfig, members: int) -> str:
    """The settings that size a run's arrays, those of its learner only (HER's are in its options)."""
    named = [n for n in ("num_envs", "buffer_size", "batch_size") if registry.reads(cfg.algo, n)]
    sizes = ", ".join(f"{n}={getattr(cfg, n)}" for n in [*named, "eval_episodes"])
    if registry.get(cfg.algo).options:
        sizes += f", {registry.get(cfg.algo).options}={getattr(cfg, registry.get(cfg.algo).options)!r}"
    return sizes + (f", {members} sweep members" if members > 1 else "")


def check_memory(need: int, what: str, device, cfg: TrainConfig, members: int) -> None:
    limit, source = device_memory(device)
    if need > limit:
        raise DoesNotFit(
            f"invalid sizes ({sizes(cfg, members)}): the run needs at least {gigabytes(need)} ({what}) "
            f"but {source} is {gigabytes(limit)}"
        )


def compile_hint(env: envs.GoalEnv) -> str:
    """Roughly how long the first compilation takes for this kind of task."""
    if type(env).__module__.startswith("envs.fetch"):
        return "1 to 3 minutes for a Fetch task on a 2-core CPU, under a minute on a GPU"
    if hasattr(type(env), "mj_model"):  # the other MuJoCo (MJX) tasks: a smaller model than Fetch's
        return "about a minute for an MJX task on a 2-core CPU, less on a GPU"
    return "about 15 s on a 2-core CPU, a few seconds on a GPU"
