"""Training a figure's methods at once, one process each (``python -m splid_jax.figures fig3 --side-by-side``).

Why: at the sizes the methods run (16 to 640 envs) each program is a chain of small kernels that leaves most of a
GPU idle. Under CUDA MPS the processes' kernels run on the GPU together, so the figure takes about as long as its
slowest method instead of their sum (BENCHMARKS.md, "Figure 3 on Push"). Without MPS a GPU runs one process's kernels
at a time, and side by side takes as long as in turn.

The parent starts one child per method (``python -m splid_jax.figures.side_by_side OUT METHOD``), each training
its sweep as ``runs.train`` would, its output in OUT/logs/METHOD.log; only the parent writes OUT/figure.json.
On a host of several GPUs the children are spread over them, one GPU each (CUDA_VISIBLE_DEVICES), and the
heaviest methods are split by seed while GPUs are to spare (``spreading``); each sweep's record names its GPU. The
children have sessions of their own, so a terminal's Ctrl-C reaches the parent alone, which passes each SIGINT or
SIGTERM on once: every child checkpoints and stops, and ``--resume`` continues them. A child whose parent is gone
stops so too.
"""

from __future__ import annotations

import argparse
import os
import signal
import subprocess
import sys
import threading
import time
from typing import NamedTuple

from splid_jax.figures import spreading
from splid_jax.figures.record import SPEC, load_record, sweeps
from splid_jax.figures.runs import train_sweep
from splid_jax.runtime import checkpoint, loop, progress
from splid_jax.runtime.run_files import METRICS, read_metrics

LOGS = "logs"
POLL_S = 0.5
REPORT_S = 30.0  # seconds between progress lines
MPS_PIPE = "/tmp/nvidia-mps"  # where CUDA MPS's control daemon listens unless CUDA_MPS_PIPE_DIRECTORY says otherwise


class Job(NamedTuple):
    method: str
    ran: dict  # the method's sweep in the figure's record
    sub: str  # its directory under OUT
    proc: subprocess.Popen
    start: float  # perf_counter at its launch


def share_gpu_memory() -> None:
    """Keeps this process and its children from taking most of the GPU's memory at their first use (JAX's
    default), so the children fit on one GPU beside each other; a value already set stays."""
    os.environ.setdefault("XLA_PYTHON_CLIENT_PREALLOCATE", "false")


def mps_running() -> bool:
    """Whether a CUDA MPS control daemon seems to listen (its pipe directory holds its control pipe)."""
    return os.path.exists(os.path.join(os.environ.get("CUDA_MPS_PIPE_DIRECTORY", MPS_PIPE), "control"))


def _on_gpu() -> bool:
    import jax

    return jax.default_backend() == "gpu"


def _compile_cache() -> str:
    import jax

    return jax.config.jax_compilation_cache_dir or ""


def child_command(out: str, method: str, resume: bool, compile_cache: str, part: str | None = None) -> list[str]:
    return (
        [sys.executable, "-m", __name__, out, method, "--compile-cache", compile_cache]
        + (["--resume"] if resume else [])
        + (["--part", part] if part else [])
    )


def child_env(gpu: str | None) -> dict[str, str]:
    """A child's environment: this process's, on the one GPU ``gpu`` when the figure is spread over several."""
    return {**os.environ, **({"CUDA_VISIBLE_DEVICES": gpu} if gpu is not None else {})}


def placed(record: dict, gpus: list[str]) -> tuple[dict, list[str | None]]:
    """``record`` with each of its sweeps placed on one of ``gpus`` (noted in the sweep's record as "gpu"),
    and each one's GPU: all None on one GPU or none, where the children share what this process sees."""
    found = sweeps(record)
    if len(gpus) < 2:
        for _, ran, _ in found:
            ran.pop("gpu", None)  # placed when started on several, not now
        return record, [None] * len(found)
    seeds = {m: 0 for m in record["methods"]}
    for method, ran, _ in found:
        seeds[method] += len(ran["members"])
    costs = [spreading.cost(m, len(ran["members"]), seeds[m], ran.get("config")) for m, ran, _ in found]
    where = spreading.assign(costs, len(gpus))
    for (_, ran, _), g in zip(found, where, strict=True):
        ran["gpu"] = gpus[g]
    return record, [gpus[g] for g in where]


def _latest_iteration(out: str, sub: str, ran: dict) -> int | None:
    """The first member's newest recorded iteration (a metrics file being written may be torn or absent)."""
    try:
        records = read_metrics(os.path.join(out, sub, ran["members"][0]["run_dir"], METRICS))
    except checkpoint.CheckpointError:
        return None
    return records[-1]["iteration"] if records else None


def train_side_by_side(out: str, record: dict, quiet: bool, resume: bool = False) -> None:
    """Trains every sweep of ``record`` at once, one child process each (with this process's compile
    cache), and notes each one's seconds in OUT/figure.json as it ends. Raises ``loop.Interrupted`` after
    passing a signal on (the children have checkpointed), ``loop.RunStopped`` naming the methods whose
    process failed and their logs."""
    gpus = spreading.visible_gpus()
    if not resume:  # a resumed figure keeps the parts it was started with
        record.update(spreading.split(record, len(gpus)))
    record, on = placed(record, gpus)
    loop.write_json(os.path.join(out, SPEC), record)  # what each child reads
    logs = os.path.join(out, LOGS)
    os.makedirs(logs, exist_ok=True)
    share_gpu_memory()  # the children inherit it
    jobs = []
    for (method, ran, sub), gpu in zip(sweeps(record), on, strict=True):
        name = sub.replace(os.sep, "-")
        part = ran.get("dir")
        with open(os.path.join(logs, f"{name}.log"), "a") as log:  # the child holds its own copy of the file
            cmd = child_command(out, method, resume, _compile_cache(), part)
            proc = subprocess.Popen(
                cmd, stdout=log, stderr=subprocess.STDOUT, start_new_session=True, env=child_env(gpu)
            )
        jobs.append(Job(name, ran, sub, proc, time.perf_counter()))
    spread = f" over GPUs {','.join(dict.fromkeys(g for g in on if g is not None))}" if len(gpus) > 1 else ""
    progress.show(f"{record['figure']}: {len(jobs)} processes side by side{spread}, their output in {logs}", quiet)
    if not mps_running() and _on_gpu():
        print(
            "warning: no CUDA MPS daemon found (nvidia-cuda-mps-control -d): the GPU runs one process's kernels "
            "at a time, and side by side takes as long as in turn",
            file=sys.stderr,
        )
    caught: list[int] = []

    def pass_on(signum, frame):
        caught.append(signum)
        for job in jobs:
            if job.proc.poll() is None:
                job.proc.send_signal(signum)

    previous = {sig: signal.signal(sig, pass_on) for sig in (signal.SIGINT, signal.SIGTERM)}
    running, t0, reported = list(jobs), time.perf_counter(), time.perf_counter()
    try:
        while running:
            time.sleep(POLL_S)
            for job in [j for j in running if j.proc.poll() is not None]:
                running.remove(job)
                job.ran["total_s"] = round(job.ran.get("total_s", 0.0) + time.perf_counter() - job.start, 1)
                loop.write_json(os.path.join(out, SPEC), record)
            if running and time.perf_counter() - reported >= REPORT_S:
                reported = time.perf_counter()
                states = [
                    f"{j.method} ended"
                    if j not in running
                    else f"{j.method} {_latest_iteration(out, j.sub, j.ran) or 0}/{j.ran['config']['iterations']}"
                    for j in jobs
                ]
                elapsed = time.perf_counter() - t0
                progress.show(f"{record['figure']} side by side, {elapsed:.0f} s: " + ", ".join(states), quiet)
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
        for job in running:  # an error here: the children stop with it, checkpointed
            job.proc.send_signal(signal.SIGTERM)
            job.proc.wait()
    if caught:
        raise loop.Interrupted(caught[0])
    failed = [(j.method, j.proc.returncode) for j in jobs if j.proc.returncode != 0]
    if failed:
        named = ", ".join(f"{m} (exit {rc}, {os.path.join(logs, m + '.log')})" for m, rc in failed)
        raise loop.RunStopped(f"{len(failed)} of {len(jobs)} methods failed: {named}; the others finished")


def stop_when_orphaned(parent: int, every_s: float = 1.0) -> threading.Thread:
    """Sends this process SIGTERM once ``parent`` is gone (killed, say, with SIGKILL, which it cannot pass on),
    so a child checkpoints and stops rather than train on unwatched; ``--resume`` continues it."""

    def watch():
        while os.getppid() == parent:
            time.sleep(every_s)
        os.kill(os.getpid(), signal.SIGTERM)

    thread = threading.Thread(target=watch, name="orphan-watch", daemon=True)
    thread.start()
    return thread


def main(argv: list[str] | None = None) -> int:
    """One child: trains METHOD's sweep of the figure in OUT, as the parent's record describes it."""
    parser = argparse.ArgumentParser(prog=f"python -m {__name__}")
    parser.add_argument("out")
    parser.add_argument("method")
    parser.add_argument("--resume", action="store_true")
    parser.add_argument("--compile-cache", default="")
    parser.add_argument("--part", default=None, help="one part (its directory) of a method split by seed")
    ns = parser.parse_args(argv)
    stop_when_orphaned(os.getppid())
    from splid_jax.cli import use_compile_cache

    use_compile_cache(ns.compile_cache)
    record = load_record(ns.out)
    found = [(m, ran, sub) for m, ran, sub in sweeps(record) if m == ns.method and ns.part in (None, ran.get("dir"))]
    if not found:
        part = f" part {ns.part!r}" if ns.part else ""
        print(f"{parser.prog}: error: no method {ns.method!r}{part} in {ns.out}", file=sys.stderr)
        return 2
    try:
        for method, ran, sub in found:
            train_sweep(ns.out, record, method, ran, sub, quiet=False, resume=ns.resume)  # the log shows progress
    except loop.Interrupted as stop:
        return stop.exit_code
    except (loop.RunStopped, checkpoint.CheckpointError) as err:
        print(f"{parser.prog}: error: {err}", file=sys.stderr)
        return 3
    return 0


def run(argv: list[str] | None = None) -> None:
    """The child process: after a signal it ends at once with its code (``exit_with``), not through Python's
    shutdown, which a chunk still running in a worker thread turns into an abort once the checkpoint is written."""
    from splid_jax.cli import exit_with

    exit_with(main(argv))


if __name__ == "__main__":
    run()
