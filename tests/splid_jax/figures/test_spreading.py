"""A side-by-side figure's processes over a host's GPUs: the heaviest split by seed while GPUs are to spare,
each process to the least loaded GPU, heaviest first (the children so placed: test_side_by_side.py)."""

from splid_jax.figures import spreading
from splid_jax.figures.record import sweeps


def record_of(methods, seeds=1):
    members = [{"run_dir": f"s{i}"} for i in range(seeds)]
    runs = {m: {"config": {"iterations": 10}, "members": members} for m in methods}
    return {"figure": "fig3", "methods": list(methods), "runs": runs}


FIG3 = ["splid", "gcsl", "pchid", "her", "es", "no-select"]


def test_on_spare_gpus_the_heaviest_methods_are_split_by_seed_and_every_seed_kept():
    record = record_of(FIG3, seeds=5)
    assert spreading.split(record, 4) == record  # as many processes as GPUs or more: unchanged
    split = spreading.split(record, 8)
    subs = [sub for _, _, sub in sweeps(split)]
    assert len(subs) == 8 and [s for s in subs if s.startswith("her/")] == [
        "her/seeds-0-1",
        "her/seeds-2-2",
        "her/seeds-3-4",
    ]  # HER, the heaviest by far, on three GPUs; the five lighter methods one each
    for method in FIG3:
        kept = [m["run_dir"] for x, ran, _ in sweeps(split) if x == method for m in ran["members"]]
        assert kept == [f"s{i}" for i in range(5)]
    assert spreading.split(record_of(["her"]), 8) == record_of(["her"])  # one seed: nothing to split


def test_the_heaviest_process_goes_first_to_the_least_loaded_gpu():
    costs = [spreading.cost(m, 5, 5) for m in FIG3]
    where = spreading.assign(costs, 2)
    assert where[FIG3.index("her")] == 0 and where[FIG3.index("splid")] == 1
    loads = [sum(c for c, g in zip(costs, where, strict=True) if g == k) for k in (0, 1)]
    assert max(loads) < sum(costs) * 0.6  # balanced, where all on one GPU would take the whole sum
    assert sorted(spreading.assign(costs, 6)) == list(range(6))  # one process a GPU


def test_mrls_her_has_a_gpu_to_itself_and_baselines_her_shares_one():
    costs = [spreading.cost(m, 5, 5, {"preset": "tuned"}) for m in FIG3]
    where = spreading.assign(costs, 2)
    assert [m for m, g in zip(FIG3, where, strict=True) if g == where[FIG3.index("her")]] == ["her"]
    paper = [spreading.cost(m, 5, 5, {"preset": "paper"}) for m in FIG3]
    assert paper[FIG3.index("her")] == spreading.cost("her-baselines", 5, 5) < costs[FIG3.index("her")]
    where = spreading.assign(paper, 2)
    assert sum(g == where[FIG3.index("her")] for g in where) > 1  # at Baselines' settings HER shares its GPU
