"""XLA:CPU (jaxlib 0.10) now and then never finishes a computation: the sweep of the TensorBoard test (point,
2 seeds, 8 envs, 5 iterations), repeated in one process until one repeat makes no progress for
``--stall-s`` seconds. It then prints every Python thread's stack and exits 3; attach ``gdb -p PID -batch
-ex 'thread apply all bt'`` before that to see XLA's threads (all idle while the caller waits).

    python experiments/cpu_hang.py --repeats 200 --stall-s 60
"""

from __future__ import annotations

import argparse
import faulthandler
import os
import sys
import tempfile
import threading
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from splid_jax import sweep  # noqa: E402

ARGS = ["--env", "point", "--seeds", "2", "--iterations", "5", "--num-envs", "8", "--eval-episodes", "8",
        "--bc-steps", "5", "--quiet", "--no-plot", "--compile-cache", ""]  # fmt: skip


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0], allow_abbrev=False)
    p.add_argument("--repeats", type=int, default=200)
    p.add_argument("--stall-s", type=float, default=60.0)
    a = p.parse_args()
    done = [time.monotonic(), 0]

    def watch() -> None:
        while time.monotonic() - done[0] < a.stall_s:
            time.sleep(1.0)
        print(f"pid {os.getpid()}: repeat {done[1] + 1} made no progress for {a.stall_s:.0f} s", flush=True)
        faulthandler.dump_traceback(all_threads=True)
        os._exit(3)

    threading.Thread(target=watch, daemon=True).start()
    for i in range(a.repeats):
        run_dir = tempfile.mkdtemp()
        t0 = time.perf_counter()
        assert sweep.main([*ARGS, "--run-dir", run_dir]) == 0
        done[:] = [time.monotonic(), i + 1]
        print(f"repeat {i + 1}: {time.perf_counter() - t0:.1f} s", flush=True)
    print(f"pid {os.getpid()}: {a.repeats} repeats, no stall")


if __name__ == "__main__":
    main()
