"""A figure's directory: OUT/figure.json (the command, device, date and what each method ran) and
where under OUT each vmapped sweep lies."""

from __future__ import annotations

import json
import os

from splid_jax.common.errors import InvalidConfig, check
from splid_jax.figures.registry import SPECS
from splid_jax.runtime import loop

SPEC = "figure.json"  # the figure's command, device, date and what each method ran


def load_record(out: str) -> dict:
    path = os.path.join(out, SPEC)
    try:
        with open(path) as fh:
            record = json.load(fh)
        check(record.get("figure") in SPECS, "replot", out, f"a figure directory ({path} names no figure)")
        return record
    except (OSError, json.JSONDecodeError):
        raise InvalidConfig("replot", out, f"a directory holding the {SPEC} a figure command wrote") from None


def sweeps(record: dict) -> list[tuple[str, dict, str]]:
    """Each vmapped sweep of the figure as (method, its record, its directory under OUT): one per method
    in METHOD/, or, in a Figure 4 or 5 merged from parts trained with distinct values, one per part in
    METHOD/PART/."""
    found = []
    for method in record["methods"]:
        ran = record["runs"][method]
        for part in ran.get("parts", [ran]):
            found.append((method, part, os.path.join(method, *([part["dir"]] if "dir" in part else []))))
    return found


def check_out(out: str) -> None:
    if os.path.isdir(out) and os.listdir(out):
        raise InvalidConfig("out", out, "a new or empty directory (--replot redraws the figure in it)")
    check(not os.path.exists(out) or os.path.isdir(out), "out", out, "a directory, not a file")
    loop.check_writable(out)
