"""Where the seconds of one ``python -m splid_jax.train`` command go, outside what it prints itself
(tracing, compiling, training): importing, the backend's start, the memory check's first device work,
the initial state, each checkpoint write and the exit. Each phase is printed to stderr, as
``[seconds since start] phase (its own seconds)``, as the command runs.

    python experiments/command_phases.py --env push --compile-cache= --run-dir /tmp/phases

Takes the train command's own flags. The wall time from outside (``time``) adds the interpreter's
start and teardown."""

from __future__ import annotations

import functools
import sys
import time

START = time.perf_counter()


def mark(what: str) -> None:
    print(f"[{time.perf_counter() - START:7.2f}s] {what}", file=sys.stderr, flush=True)


def timed(owner, name: str, block: bool = False) -> None:
    """Replace ``owner.name`` by a version that marks its seconds (after its device work, with ``block``)."""
    fn = getattr(owner, name)

    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        t0 = time.perf_counter()
        out = fn(*args, **kwargs)
        if block:
            jax.block_until_ready(out)
        mark(f"{name} ({time.perf_counter() - t0:.2f} s)")
        return out

    setattr(owner, name, wrapper)


from splid_jax import train  # noqa: E402

mark("imported")
import jax  # noqa: E402

jax.devices()
mark(f"backend ready ({jax.default_backend()})")

from splid_jax.config import TrainConfig  # noqa: E402
from splid_jax.runtime import checkpoint, loop  # noqa: E402

timed(TrainConfig, "make_env")
timed(loop, "initial_state", block=True)
timed(checkpoint, "save")
timed(loop._Loop, "check_state_fits")

if __name__ == "__main__":
    code = train.main(sys.argv[1:])
    mark(f"exit {code}")
    sys.exit(code)
