"""``python -m splid_jax.figures FIG --env ENV``: the paper's figures, each from one command.

Every series is trained through the one host loop (``splid_jax.runtime.loop``) as one vmapped sweep whose
members are the seeds (and, for Figures 4 and 5, the values of H or sigma), in OUT/METHOD/. Every
method gets the same budget of exploration episodes: its iterations are the budget over its
episodes per iteration, rounded to whole compiled chunks, and the CSV says what each one ran. The
figure and its CSV are drawn from the run directories alone, so ``--replot`` redraws them without
training; OUT/figure.json records the command, the device and the date.

The modules, one job each: ``registry`` (the figures and methods), ``settings`` (``--methods``,
``--values``, ``--set``), ``planning`` (each method's sweep for the budget), ``record`` (OUT/figure.json
and the sweeps' directories), ``runs`` (training), ``side_by_side`` (the methods at once, one process
each), ``merging`` (parts trained apart), ``series`` (statistics over seeds, from
``splid_jax.common.stats``), ``table`` (the CSV), ``drawing`` (the PNG) and ``cli``. Their public names are
reachable from this package too; they load on first use, so that ``python -m splid_jax.figures`` can set
its signal handlers before JAX loads."""

from __future__ import annotations

from splid_jax.common.lazy import lazy_names

_HOMES = {
    "splid_jax.figures.registry": ("METHODS", "SHORT", "SPECS", "SUCCESS", "Method", "Spec", "member_name"),
    "splid_jax.figures.settings": ("OWNED", "parse_methods", "parse_sets", "parse_values", "reads"),
    "splid_jax.figures.planning": (
        "BUDGETS",
        "QUICK_EPISODES",
        "QUICK_FIELDS",
        "QUICK_METHOD_FIELDS",
        "Plan",
        "default_budget",
        "describe",
        "device_name",
        "plan",
    ),
    "splid_jax.figures.record": ("SPEC", "check_out", "load_record", "sweeps"),
    "splid_jax.figures.runs": ("train", "train_sweep"),
    "splid_jax.figures.side_by_side": ("mps_running", "train_side_by_side"),
    "splid_jax.figures.merging": ("merge",),
    "splid_jax.figures.series": ("MEASURES", "Series", "load_series"),
    "splid_jax.figures.table": ("write_csv",),
    "splid_jax.figures.drawing": ("draw", "render", "title"),
    "splid_jax.figures.cli": ("HELP", "build_parser", "main"),
    "splid_jax.common.errors": ("InvalidConfig",),
}
__getattr__, __dir__, __all__ = lazy_names(__name__, _HOMES)
