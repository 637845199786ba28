"""A side-by-side figure's processes spread over the GPUs of a host.

While there are more GPUs than processes, the heaviest method's heaviest sweep is split by seed into two
(METHOD/seeds-A-B/, a part each, as a merged figure keeps its parts); then each process goes to the GPU with
the least estimated work so far, heaviest first (longest processing time first). A split member runs in a
vmapped program of another size, which may round differently (README, "--num-devices")."""

from __future__ import annotations

import copy
import os

# Each method's relative seconds at a figure's equal budget of episodes: its process's time in Figure 3 on
# Push, six methods side by side on one GPU (BENCHMARKS.md, "Figure 3 on Push"), HER at Baselines' settings
# ("her-baselines", or "her" run with the paper preset). HER at mrl's settings ("her", the default) is its
# 5 seeds' time alone on a GPU at that budget (BENCHMARKS.md, "Time budget per stage", 8 envs): a GPU's work,
# so it comes first and shares least. Other methods count as the heaviest.
COST = {
    "her": 3625.0, "her-baselines": 1475.0, "splid": 902.0, "pchid": 860.0, "no-select": 722.0, "gcsl": 721.0,
    "es": 391.0,
}  # fmt: skip
# The share of a sweep's time taken as independent of its member count (a chain of small kernels whose time
# barely depends on the batch); an estimate, which only orders and balances the processes.
FIXED = 0.5


def visible_gpus() -> list[str]:
    """The CUDA device of each GPU this process sees, as a child's CUDA_VISIBLE_DEVICES names it; none off a GPU."""
    import jax

    if jax.default_backend() != "gpu":
        return []
    count = jax.local_device_count()
    named = os.environ.get("CUDA_VISIBLE_DEVICES")
    return named.split(",")[:count] if named else [str(i) for i in range(count)]


def cost(method: str, members: int, seeds: int, config: dict | None = None) -> float:
    """``config``: the sweep's recorded settings; HER run with the paper preset costs as Baselines' HER."""
    if method == "her" and (config or {}).get("preset") == "paper":
        method = "her-baselines"
    whole = COST.get(method, max(COST.values()))
    return whole * (FIXED + (1 - FIXED) * members / max(seeds, 1))


def split(record: dict, gpus: int) -> dict:
    """``record`` with its heaviest sweeps halved by seed while it has fewer sweeps than ``gpus``; a method
    already in parts (a merged or split figure) stays as it is."""
    record = copy.deepcopy(record)
    seeds = {m: len(ran["members"]) for m, ran in record["runs"].items() if "parts" not in ran}
    parts = {m: [record["runs"][m]["members"]] for m in seeds}
    kept = sum(len(ran["parts"]) for ran in record["runs"].values() if "parts" in ran)
    while kept + sum(map(len, parts.values())) < gpus:
        heaviest = [
            (cost(m, len(p), seeds[m], record["runs"][m].get("config")), m, i)
            for m, ps in parts.items()
            for i, p in enumerate(ps)
            if len(p) > 1
        ]
        if not heaviest:
            break
        _, m, i = max(heaviest)
        halves = parts[m].pop(i)
        first = (len(halves) + 1) // 2
        parts[m][i:i] = [halves[:first], halves[first:]]
    for m, ps in parts.items():
        if len(ps) > 1:
            ran = record["runs"][m]
            at = 0
            record["runs"][m] = {"parts": []}
            for p in ps:
                name = f"seeds-{at}-{at + len(p) - 1}"
                record["runs"][m]["parts"].append({**ran, "members": p, "dir": name})
                at += len(p)
    return record


def assign(costs: list[float], gpus: int) -> list[int]:
    """The GPU of each process: heaviest first, each to the GPU with the least estimated work so far."""
    load, where = [0.0] * gpus, [0] * len(costs)
    for i in sorted(range(len(costs)), key=lambda i: -costs[i]):
        where[i] = min(range(gpus), key=lambda g: (load[g], g))
        load[where[i]] += costs[i]
    return where
