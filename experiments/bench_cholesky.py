"""Factor-and-solve of a batch of small SPD matrices: ``jax.scipy.linalg`` (batched cuSOLVER / cuBLAS
calls on a GPU) against ``envs.small_cholesky`` (unrolled element-wise arithmetic), the two peers
timed in the same run.

Each timed program applies ``cho_solve(cho_factor(A), x)`` ``--repeat`` times in a ``fori_loop``
to a vmapped batch, each solve feeding the next right-hand side and, through a tiny shift of the
diagonal, the next matrix (so that XLA cannot hoist the factorisation out of the loop); the median
of ``--repeats`` timed calls after a warm-up call, divided by that count, gives the time per
factor-and-solve of the batch.

    python experiments/bench_cholesky.py --n 9 11 --batch 65536
    python experiments/bench_cholesky.py --n 9 --batch 256 --repeats 2      # CPU smoke test
"""

from __future__ import annotations

import argparse
import functools
import json
import sys
import time
from pathlib import Path

import jax
import jax.numpy as jnp
import jax.scipy.linalg as jsl

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from bench_splid import timed  # noqa: E402

from envs import small_cholesky  # noqa: E402

PEERS = {
    "jax.scipy.linalg": lambda a, b: jsl.cho_solve(jsl.cho_factor(a), b),
    "unrolled": lambda a, b: small_cholesky.cho_solve(small_cholesky.cho_factor(a), b),
}


def spd_batch(key, batch: int, n: int):
    """Random SPD matrices shaped like a Newton Hessian (M + J^T D J with 48 rows) and right-hand sides."""
    k1, k2 = jax.random.split(key)
    j = jax.random.normal(k1, (batch, n, 48))
    a = j @ jnp.swapaxes(j, -1, -2) / 48 + jnp.eye(n)
    return a, jax.random.normal(k2, (batch, n))


def step(fn, m, y):
    shift = 1e-3 * jnp.tanh(jnp.sum(y))  # depends on the carry: no loop-invariant factorisation
    return fn(m + shift * jnp.eye(m.shape[-1], dtype=m.dtype), y)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--n", type=int, nargs="+", default=[9], help="matrix sizes")
    p.add_argument("--batch", type=int, default=65536)
    p.add_argument("--repeat", type=int, default=20, help="factor-and-solves per timed program")
    p.add_argument("--repeats", type=int, default=5)
    p.add_argument("--out", type=Path, default=None)
    a = p.parse_args(argv)
    if min(a.batch, a.repeat, a.repeats, *a.n) < 1 or max(a.n) > small_cholesky.MAX_UNROLLED:
        p.error(f"--batch, --repeat, --repeats must be >= 1 and --n in [1, {small_cholesky.MAX_UNROLLED}]")
    dev = jax.devices()[0]
    print(f"device {dev.device_kind} ({jax.default_backend()}), jax {jax.__version__}, batch {a.batch}")
    rows = []
    for n in a.n:
        mats, rhs = spd_batch(jax.random.PRNGKey(n), a.batch, n)
        ref = jax.jit(jax.vmap(PEERS["jax.scipy.linalg"]))(mats, rhs)
        for name, fn in PEERS.items():
            err = float(jnp.max(jnp.abs(jax.jit(jax.vmap(fn))(mats, rhs) - ref)) / jnp.max(jnp.abs(ref)))
            one = jax.vmap(functools.partial(step, fn))
            prog = jax.jit(lambda m, x, one=one: jax.lax.fori_loop(0, a.repeat, lambda _, y: one(m, y), x))
            stats, _ = timed(prog, mats, rhs, repeats=a.repeats)
            row = {"n": n, "peer": name, "ms": 1e3 * stats["median_s"] / a.repeat, "compile_s": stats["compile_s"],
                   "max_rel_diff_vs_library": err}  # fmt: skip
            rows.append(row)
            print(f"n={n:2d} {name:18s} {row['ms']:.4f} ms per batch  (compile {row['compile_s']:.1f} s, "
                  f"max rel. diff from the library {err:.1e})")  # fmt: skip
        lib, own = rows[-2]["ms"], rows[-1]["ms"]
        print(f"n={n:2d} unrolled is {lib / own:.2f}x the library")
    if a.out:
        meta = {"device": dev.device_kind, "backend": jax.default_backend(), "jax": jax.__version__,
                "batch": a.batch, "date": time.strftime("%Y-%m-%d"), "argv": sys.argv[1:]}  # fmt: skip
        a.out.write_text(json.dumps({"meta": meta, "rows": rows}, indent=1))
        print(f"wrote {a.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
