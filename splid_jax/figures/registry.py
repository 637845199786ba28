"""The figures and the methods they train: what each figure draws, and the TrainConfig fields that
make each method."""

from __future__ import annotations

import dataclasses
from typing import Any


@dataclasses.dataclass(frozen=True)
class Method:
    label: str
    fields: dict[str, Any]  # the TrainConfig fields that make the method


METHODS: dict[str, Method] = {
    "splid": Method("SPLID", {"algo": "splid", "select": True}),
    "gcsl": Method("GCSL", {"algo": "gcsl"}),
    "pchid": Method("PCHID", {"algo": "pchid"}),
    "her": Method("HER", {"algo": "her"}),  # its legend also names whose settings it ran: mrl's or Baselines'
    "es": Method("ES (OpenAI-ES)", {"algo": "es"}),
    "no-select": Method("SPLID without SELECT", {"algo": "splid", "select": False}),
    # the HER of the paper's Figure 3 beside the default one: --methods ...,her,her-baselines
    "her-baselines": Method("HER (Baselines)", {"algo": "her", "preset": "paper"}),
}


@dataclasses.dataclass(frozen=True)
class Spec:
    """What one figure trains and draws."""

    title: str
    methods: tuple[str, ...]  # the methods it trains, in legend order
    panels: tuple[tuple[str, str], ...]  # (metric, panel title)
    vary: str | None = None  # a config field whose values a sweep spans, one series each
    values: tuple = ()  # its values by default


SUCCESS = (("eval_success", "success at any step"), ("eval_success_final", "success at the final step"))
SPECS: dict[str, Spec] = {
    "fig3": Spec("SPLID against its baselines", ("splid", "gcsl", "pchid", "her", "es", "no-select"), SUCCESS),
    "fig4": Spec("SPLID's learning horizon H", ("splid",), SUCCESS, "horizon", (1, 2, 4, 8, 16)),
    "fig5": Spec("SPLID's exploration factor sigma", ("splid",), SUCCESS, "sigma", (0.25, 0.5, 1.0, 2.0)),
    "fig6": Spec("SPLID with and without SELECT", ("splid", "no-select"), (("eval_return", "average return"),)),
}
# The paper's Figures 8 and 9 are the same runs (SPLID and GCSL on its appendix tasks) drawn as average
# return and as success: here one figure with both, made by either name.
SPECS["fig8"] = SPECS["fig9"] = Spec(
    "SPLID against GCSL", ("splid", "gcsl"), (("eval_return", "average return"),) + SUCCESS
)
SHORT = {"horizon": "H", "sigma": "sigma"}  # a swept field's name in member names and labels


def member_name(seed: int, vary: str | None, value) -> str:
    return f"s{seed}" if vary is None else f"{SHORT[vary]}{value:g}-s{seed}"
