"""JAX's persistent compile cache as the suite's processes share it: entries written whole, and written by
every process of a multi-process run. ``python -m tests.compile_cache MODULE ARGS...`` runs ``python -m
MODULE ARGS...`` so."""

from __future__ import annotations

import os
import runpy
import sys
import tempfile


def atomic_writes() -> None:
    """JAX writes a cache entry in place, unlocked unless the cache is bounded: another process could read
    a half-written program (JAX then warns and compiles it). Written beside and renamed into place, an
    entry is whole or absent. Another JAX's cache: as it is."""
    try:
        from jax._src import lru_cache
    except ImportError:
        return
    put = getattr(lru_cache.LRUCache, "put", None)
    if put is None or getattr(put, "atomic", False):
        return

    def atomic_put(self, key: str, value: bytes) -> None:
        path = os.path.join(str(self.path), f"{key}{lru_cache._CACHE_SUFFIX}")
        if self.eviction_enabled or "://" in path or os.path.exists(path):  # bounded, remote, or there already
            return put(self, key, value)
        fd, part = tempfile.mkstemp(dir=os.path.dirname(path), prefix=".part-")
        with os.fdopen(fd, "wb") as fh:
            fh.write(value)
        os.replace(part, path)

    atomic_put.atomic = True
    lru_cache.LRUCache.put = atomic_put


class _AsProcess0:
    """``jax.distributed``'s state as JAX's compiler reads it, with the process index 0."""

    process_id = 0

    def __init__(self, real):
        self._real = real

    def __getattr__(self, name):
        return getattr(self._real, name)


class _Distributed:
    def __init__(self, module):
        self._module = module
        self.global_state = _AsProcess0(module.global_state)

    def __getattr__(self, name):
        return getattr(self._module, name)


def from_every_process() -> None:
    """JAX writes cache entries from process 0 alone (against write contention on shared file systems): a
    resumed process 1 would compile its programs again. Here its compiler sees itself as process 0 when it
    decides whether to write; nothing else of the run changes. Another JAX's compiler: as it is."""
    try:
        from jax._src import compiler, distributed
    except ImportError:
        return
    if getattr(compiler, "distributed", None) is distributed:
        compiler.distributed = _Distributed(distributed)


if __name__ == "__main__":
    atomic_writes()
    from_every_process()
    module, sys.argv = sys.argv[1], sys.argv[1:]
    runpy.run_module(module, run_name="__main__", alter_sys=True)
