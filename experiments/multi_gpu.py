"""One GPU against N of the same host, in one call: a sweep, Figure 3 side by side, a single large run, and two
processes under jax.distributed (issues "Every GPU of a host" and "Figure 3 on 4 and 8 GPUs").

    python experiments/multi_gpu.py OUT --gpus N [--parts sweep,single,figure,processes] [--budget-s 510]

- sweep: an 8-seed Push sweep of 10 iterations (--sweep-*), --num-devices 1 against N: episodes per second over the
  chunks after the first (from the members' metrics, whose clock starts after the compile), compile and wall seconds;
- single: one PickAndPlace SPLID run at 4,096 envs for 4 iterations (--single-*), its envs split over 1 against N
  GPUs: seconds per iteration after the first chunk, compile and wall seconds, or the error that stopped it;
- figure: Figure 3 on Push at 1,000 episodes a method (--figure-episodes), --side-by-side on 1 GPU against N (under
  CUDA MPS, started here if no daemon runs and stopped after): the whole command's seconds and each process's;
- processes: a 2-seed sweep as two processes of one GPU each under jax.distributed (last, so run only where time
  is left: --parts processes alone takes about 2 min).

Each part runs its 1-GPU side, then its N-GPU side (CUDA_VISIBLE_DEVICES), or both at once with --concurrent (the
1-GPU side on GPU N, so N + 1 GPUs), the compile cache off on both. Expected on H100s, in turn: sweep about 2.5 min,
single about 3.5 min, figure about 4 min at 1,000 episodes (Figure 3 at 20,000 episodes takes about 7 min on one
GPU alone: a call of its own, --parts figure --figure-episodes 20000, on a host where --concurrent applies). A part
whose estimate exceeds what is left of --budget-s is skipped and said so, and every command stops at the budget, so
the script ends within it. Runs write under a scratch directory that is removed; OUT gets results.json (every
number), summary.txt (the table) and logs.txt (each command and the tail of its output). On a CPU host the "GPUs"
are host devices (XLA_FLAGS=--xla_force_host_platform_device_count=N): small sizes (--sweep-env point --single-env
point ...) try the script itself.
"""

from __future__ import annotations

import argparse
import glob
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import threading
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PARTS = ("sweep", "figure", "single", "processes")
T0 = time.monotonic()


def say(text: str) -> None:
    print(f"[{time.monotonic() - T0:6.0f} s] {text}", flush=True)


def env_for(gpus: int, first: int = 0) -> dict:
    """This process's environment on ``gpus`` GPUs from GPU ``first`` on, NVLink multicast off, the repository
    first on the path."""
    env = dict(os.environ)
    env["CUDA_VISIBLE_DEVICES"] = ",".join(str(first + i) for i in range(gpus))
    env["NCCL_NVLS_ENABLE"] = "0"
    env["PYTHONPATH"] = os.pathsep.join([ROOT, *filter(None, [os.environ.get("PYTHONPATH")])])
    return env


class Runner:
    def __init__(self, out: str, budget_s: float):
        self.out, self.budget_s = out, budget_s
        self.logs: list[str] = []

    def left(self) -> float:
        return self.budget_s - (time.monotonic() - T0)

    def sides(self, name: str, build, a: argparse.Namespace) -> dict:
        """``build(gpus)``'s command on 1 GPU and on N, one after the other, or with ``--concurrent`` at once, the
        1-GPU side on GPU N (the N+1-th); the results by side ("1", "N")."""
        first = {1: a.gpus if a.concurrent else 0, a.gpus: 0}
        todo = {g: (f"{name} on {g} GPU(s)", build(g), env_for(g, first[g])) for g in (1, a.gpus)}
        if not a.concurrent:
            return {str(g): self.run(*job) for g, job in todo.items()}
        got: dict = {}
        threads = [
            threading.Thread(target=lambda g=g, job=job: got.update({str(g): self.run(*job)}))
            for g, job in todo.items()
        ]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        return got

    def run(self, name: str, cmd: list[str], env: dict) -> dict:
        """``cmd``'s exit code, wall seconds and output, stopped at what is left of the budget."""
        say(f"{name}: {' '.join(cmd)}")
        t0 = time.monotonic()
        try:
            done = subprocess.run(cmd, env=env, cwd=ROOT, capture_output=True, text=True, timeout=max(self.left(), 1))
            rc, text = done.returncode, done.stdout + done.stderr
        except subprocess.TimeoutExpired as e:
            rc = "timeout"
            text = (e.stdout or b"").decode(errors="replace") + (e.stderr or b"").decode(errors="replace")
        wall = time.monotonic() - t0
        tail = "\n".join(text.splitlines()[-60:])
        self.logs.append(f"=== {name} (exit {rc}, {wall:.1f} s)\n$ {' '.join(cmd)}\n{tail}\n")
        say(f"{name}: exit {rc} after {wall:.1f} s")
        return {"rc": rc, "wall_s": round(wall, 1), "output": text}


def metrics(path: str) -> list[dict]:
    try:
        with open(path) as fh:
            return [json.loads(line) for line in fh if line.strip()]
    except (OSError, json.JSONDecodeError):
        return []


def compile_s(text: str) -> float | None:
    found = re.findall(r"compiled in ([\d.]+) s", text)
    return float(found[0]) if found else None


def rate(runs: list[list[dict]]) -> dict:
    """Episodes per second over the chunks after the first (the first may carry warm-up), summed over the
    members, and seconds per iteration; from the metrics' own wall clock, which starts after the compile."""
    runs = [r for r in runs if len(r) >= 2]
    if not runs:
        return {}
    first, last = runs[0][0], runs[0][-1]
    span = last["wall_s"] - first["wall_s"]
    episodes = sum(r[-1]["episodes"] - r[0]["episodes"] for r in runs)
    return {
        "episodes_per_s": round(episodes / span, 1),
        "s_per_iteration": round(span / (last["iteration"] - first["iteration"]), 4),
        "members": len(runs),
        "eval_success_mean": round(sum(r[-1]["eval_success"] for r in runs) / len(runs), 4),
    }


def sweep(r: Runner, a: argparse.Namespace, scratch: str) -> dict:
    def build(gpus):
        return [sys.executable, "-m", "splid_jax.sweep", "--env", a.sweep_env, "--seeds", str(a.sweep_seeds),
                "--iterations", str(a.sweep_iterations), "--eval-every", str(a.sweep_eval_every), "--num-devices",
                str(gpus), "--checkpoint-every", "0", "--compile-cache", "", "--no-plot", "--run-dir",
                os.path.join(scratch, f"sweep-{gpus}"), *a.sweep_args.split()]  # fmt: skip

    out = {}
    for side, done in r.sides("sweep", build, a).items():
        run_dir = os.path.join(scratch, f"sweep-{side}")
        runs = [metrics(p) for p in sorted(glob.glob(os.path.join(run_dir, "*", "metrics.jsonl")))]
        configs = sorted(glob.glob(os.path.join(run_dir, "*", "config.json")))
        placed = [json.load(open(p)).get("devices") for p in configs[:: max(len(configs) - 1, 1)]]
        out[side] = {"rc": done["rc"], "wall_s": done["wall_s"], "compile_s": compile_s(done["output"]),
                     **rate(runs), "devices_of_first_and_last_member": placed}  # fmt: skip
        shutil.rmtree(run_dir, ignore_errors=True)
    one, many = out.get("1", {}), out.get(str(a.gpus), {})
    if one.get("episodes_per_s") and many.get("episodes_per_s"):
        out["ratio_episodes_per_s"] = round(many["episodes_per_s"] / one["episodes_per_s"], 3)
        out["ratio_wall"] = round(one["wall_s"] / many["wall_s"], 3)
    return out


def figure(r: Runner, a: argparse.Namespace, scratch: str) -> dict:
    out = {"episodes": a.figure_episodes}
    mps = shutil.which("nvidia-cuda-mps-control")
    started = False
    if mps and not os.path.exists("/tmp/nvidia-mps/control"):
        started = subprocess.run([mps, "-d"], capture_output=True).returncode == 0
        say(f"CUDA MPS control daemon started: {started}")
        time.sleep(1)
    out["mps"] = bool(mps)
    where = a.figure_out or scratch
    try:

        def build(gpus):
            return [sys.executable, "-m", "splid_jax.figures", "fig3", "--env", a.figure_env, "--episodes",
                    str(a.figure_episodes), "--side-by-side", "--set", "checkpoint_every=0", "--compile-cache", "",
                    "--out", os.path.join(where, f"fig3-{gpus}"), "--quiet", *a.figure_args.split()]  # fmt: skip

        for side, done in r.sides("figure 3", build, a).items():
            fig = os.path.join(where, f"fig3-{side}")
            try:
                record = json.load(open(os.path.join(fig, "figure.json")))
                per = {}
                for m, top in record["runs"].items():
                    for ran in top.get("parts", [top]):
                        name = f"{m}-{ran['dir']}" if "dir" in ran else m
                        try:
                            compiled = compile_s(open(os.path.join(fig, "logs", f"{name}.log")).read())
                        except OSError:
                            compiled = None
                        per[name] = {"total_s": ran.get("total_s"), "compile_s": compiled, "gpu": ran.get("gpu")}
            except (OSError, json.JSONDecodeError, KeyError):
                per = {}
            out[side] = {"rc": done["rc"], "wall_s": done["wall_s"], "processes": per}
            if not a.figure_out:
                shutil.rmtree(fig, ignore_errors=True)
    finally:
        if started:
            subprocess.run([mps], input="quit\n", text=True, capture_output=True)
    one, many = out.get("1", {}), out.get(str(a.gpus), {})
    if one.get("rc") == 0 and many.get("rc") == 0:
        out["ratio_wall"] = round(one["wall_s"] / many["wall_s"], 3)
    return out


def single(r: Runner, a: argparse.Namespace, scratch: str) -> dict:
    out = {"env": a.single_env, "num_envs": a.single_envs}

    def build(gpus):
        return [sys.executable, "-m", "splid_jax.train", "--env", a.single_env, "--num-envs", str(a.single_envs),
                "--iterations", str(a.single_iterations), "--eval-every", str(a.single_eval_every), "--num-devices",
                str(gpus), "--checkpoint-every", "0", "--compile-cache", "", "--run-dir",
                os.path.join(scratch, f"single-{gpus}"), *a.single_args.split()]  # fmt: skip

    for side, done in r.sides(f"single {a.single_env} run", build, a).items():
        run_dir = os.path.join(scratch, f"single-{side}")
        got = rate([metrics(os.path.join(run_dir, "metrics.jsonl"))])
        error = [line for line in done["output"].splitlines() if "error" in line.lower()][-1:]
        out[side] = {"rc": done["rc"], "wall_s": done["wall_s"], "compile_s": compile_s(done["output"]), **got,
                     **({"error": error[0][-300:]} if done["rc"] != 0 and error else {})}  # fmt: skip
        shutil.rmtree(run_dir, ignore_errors=True)
    one, many = out.get("1", {}), out.get(str(a.gpus), {})
    if one.get("s_per_iteration") and many.get("s_per_iteration"):
        out["ratio_per_iteration"] = round(one["s_per_iteration"] / many["s_per_iteration"], 3)
    return out


def processes(r: Runner, a: argparse.Namespace, scratch: str) -> dict:
    """The sweep as two processes of one GPU each under jax.distributed, against its members in one process."""
    run_dir = os.path.join(scratch, "processes")
    port = 20000 + os.getpid() % 20000
    base = [sys.executable, "-m", "splid_jax.sweep", "--env", a.sweep_env, "--seeds", "2", "--iterations",
            str(a.sweep_eval_every * 2), "--eval-every", str(a.sweep_eval_every), "--checkpoint-every", "0",
            "--compile-cache", "", "--no-plot", *a.sweep_args.split()]  # fmt: skip
    say("two processes, one GPU each, one sweep of 2 seeds")
    procs, t0 = [], time.monotonic()
    logs = [os.path.join(scratch, f"process-{i}.log") for i in range(2)]
    for i in range(2):
        cmd = [*base, "--run-dir", f"{run_dir}-{i}", "--coordinator", f"127.0.0.1:{port}", "--num-processes", "2",
               "--process-id", str(i)]  # fmt: skip
        env = env_for(1)
        env["CUDA_VISIBLE_DEVICES"] = str(i % max(a.gpus, 1))
        with open(logs[i], "w") as log:
            procs.append(subprocess.Popen(cmd, env=env, cwd=ROOT, stdout=log, stderr=subprocess.STDOUT))
    codes = []
    for p in procs:
        try:
            codes.append(p.wait(timeout=max(r.left(), 1)))
        except subprocess.TimeoutExpired:
            p.kill()
            codes.append("timeout")
    wall = time.monotonic() - t0
    for i, path in enumerate(logs):
        text = open(path).read()
        r.logs.append(f"=== process {i} of 2 (exit {codes[i]}, {wall:.1f} s)\n" + "\n".join(text.splitlines()[-60:]))
    out = {"rc": codes, "wall_s": round(wall, 1)}
    runs = [metrics(p) for p in sorted(glob.glob(os.path.join(f"{run_dir}-0", "*", "metrics.jsonl")))]
    out.update(rate(runs))
    for i in range(2):
        shutil.rmtree(f"{run_dir}-{i}", ignore_errors=True)
    return out


def estimate(part: str, a: argparse.Namespace) -> float:
    """Seconds a part is expected to take on H100s (the process's start, tracing and compiling at a minute to a
    minute and a half a side, then the training at the sizes asked), both sides in turn, or the longer of them
    with --concurrent. A guess from one-GPU runs, to skip a part that cannot end in time."""
    if part == "sweep":
        sides = [60 + a.sweep_iterations * 0.8] * 2
    elif part == "figure":  # HER's cycles of 16 episodes: about 0.56 s shared with five methods, 0.12 s alone
        sides = [90 + a.figure_episodes / 16 * 0.56, 90 + a.figure_episodes / 16 * 0.2]
    elif part == "single":
        sides = [75 + a.single_iterations * 6.0] * 2
    else:
        return 120 + a.sweep_eval_every * 2 * 1.0
    return max(sides) if a.concurrent else sum(sides)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("out", help="directory for results.json, summary.txt and logs.txt")
    p.add_argument("--gpus", type=int, required=True, help="N: the GPUs of the N-GPU side (the first N)")
    p.add_argument("--parts", default="sweep,single,figure,processes", help="comma-separated, of " + ", ".join(PARTS))
    p.add_argument("--budget-s", type=float, default=510.0, help="seconds for the whole script (default 510)")
    p.add_argument("--sweep-env", default="push")
    p.add_argument("--sweep-seeds", type=int, default=8)
    p.add_argument("--sweep-iterations", type=int, default=10)
    p.add_argument("--sweep-eval-every", type=int, default=5)
    p.add_argument("--sweep-args", default="", help="more sweep flags, space-separated")
    p.add_argument("--figure-env", default="push")
    p.add_argument("--figure-episodes", type=int, default=1000, help="Figure 3's budget per method (default 1,000)")
    p.add_argument("--figure-args", default="", help="more figures flags, space-separated (e.g. --quick --seeds 2)")
    p.add_argument("--figure-out", default=None, help="keep the figures in DIR/fig3-1, DIR/fig3-N (default: removed)")
    p.add_argument("--single-env", default="pick_and_place")
    p.add_argument("--single-envs", type=int, default=4096)
    p.add_argument("--single-iterations", type=int, default=4)
    p.add_argument("--single-eval-every", type=int, default=2)
    p.add_argument("--single-args", default="", help="more train flags, space-separated")
    p.add_argument(
        "--concurrent",
        action="store_true",
        help="each part's two sides at once, the 1-GPU side on GPU N "
        "(needs N + 1 GPUs); without it one after the other",
    )
    p.add_argument("--scratch", default=None, help="where runs are written, then removed (default: a new temp dir)")
    a = p.parse_args(argv)
    parts = [x for x in a.parts.split(",") if x]
    unknown = [x for x in parts if x not in PARTS]
    if unknown or a.gpus < 2:
        p.error(f"unknown part(s) {unknown}" if unknown else "--gpus must be >= 2")
    os.makedirs(a.out, exist_ok=True)
    scratch = tempfile.mkdtemp(prefix="multi-gpu-", dir=a.scratch)
    r = Runner(a.out, a.budget_s)
    results: dict = {"gpus": a.gpus, "parts": parts, "argv": sys.argv[1:] if argv is None else argv}
    # asked of a child: JAX in this process would take most of each GPU's memory from the runs
    probe = "import jax; print(jax.__version__, [f'{d.platform}:{d.id} {d.device_kind}' for d in jax.devices()])"
    seen = subprocess.run([sys.executable, "-c", probe], env=env_for(a.gpus), capture_output=True, text=True)
    results["devices"] = seen.stdout.strip() or seen.stderr.strip()[-300:]
    results["cpus"] = os.cpu_count()
    if shutil.which("nvidia-smi"):  # how the GPUs are linked, for where scaling falls short
        topo = subprocess.run(["nvidia-smi", "topo", "-m"], capture_output=True, text=True)
        results["topology"] = topo.stdout.strip().splitlines()[: 2 + a.gpus]
    say(f"devices: {results['devices']}; parts {parts}; budget {a.budget_s:.0f} s")
    done_fns = {"sweep": sweep, "figure": figure, "single": single, "processes": processes}
    try:
        for part in parts:
            need = estimate(part, a)
            if need > 1.25 * r.left():  # every command also stops at the budget
                results[part] = {"skipped": f"estimated {need:.0f} s, {r.left():.0f} s left of the budget"}
                say(f"{part}: skipped ({results[part]['skipped']})")
                continue
            say(f"{part}: starting (estimated {need:.0f} s, {r.left():.0f} s left)")
            results[part] = done_fns[part](r, a, scratch)
            write(a.out, results, r.logs)
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
        results["total_s"] = round(time.monotonic() - T0, 1)
        write(a.out, results, r.logs)
    say(f"done in {results['total_s']:.0f} s: {os.path.join(a.out, 'summary.txt')}")
    print(open(os.path.join(a.out, "summary.txt")).read())
    return 0


def write(out: str, results: dict, logs: list[str]) -> None:
    with open(os.path.join(out, "results.json"), "w") as fh:
        json.dump(results, fh, indent=1)
    with open(os.path.join(out, "logs.txt"), "w") as fh:
        fh.write("\n".join(logs))
    lines = [f"devices: {results.get('devices')}", f"N = {results['gpus']} GPUs; total {results.get('total_s')} s"]
    n = str(results["gpus"])
    for part in PARTS:
        got = results.get(part)
        if got is None:
            continue
        if "skipped" in got:
            lines.append(f"{part}: skipped, {got['skipped']}")
            continue
        if part == "processes":
            lines.append(
                f"processes: exit codes {got.get('rc')}, {got.get('wall_s')} s, {got.get('episodes_per_s')} ep/s"
            )
            continue
        for side in ("1", n):
            s = got.get(side, {})
            keys = ("rc", "wall_s", "compile_s", "episodes_per_s", "s_per_iteration")
            lines.append(f"{part} on {side} GPU(s): " + ", ".join(f"{k} {s.get(k)}" for k in keys if k in s))
        ratios = {k: v for k, v in got.items() if k.startswith("ratio")}
        lines.append(f"{part}: N against 1: {ratios or 'no ratio (a side failed or was cut short)'}")
    with open(os.path.join(out, "summary.txt"), "w") as fh:
        fh.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    sys.exit(main())
