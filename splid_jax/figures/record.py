"""A figure's directory: OUT/figure.json (the command, device, date and what each method ran) and
where under OUT each vmapped sweep lies."""

from __future__ import annotations

import json
import os

from splid_jax.common.errors import InvalidConfig, check
from splid_jax.common.paths import is_utf8
from splid_jax.figures.registry import SPECS
from splid_jax.runtime import lock, loop

SPEC = "figure.json"  # the figure's command, device, date and what each method ran


def load_record(out: str, field: str = "out") -> dict:
    """OUT/figure.json; a missing or unreadable one is blamed on ``field``, the flag that named OUT."""
    path = os.path.join(out, SPEC)
    try:
        with open(path) as fh:
            record = json.load(fh)
        check(isinstance(record, dict) and record.get("figure") in SPECS, field, out,
              f"a figure directory ({path} names no figure)")  # fmt: skip
        return record
    except (OSError, ValueError) as e:  # absent, unreadable, not UTF-8 or not JSON
        why = "" if isinstance(e, FileNotFoundError | ValueError) else f" ({e.strerror})"
        raise InvalidConfig(field, out, f"a directory holding the {SPEC} a figure command wrote{why}") from None


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
    check(is_utf8(out), "out", out, "a path of UTF-8 text (checkpoints are written under it)")
    if os.path.isdir(out) and set(os.listdir(out)) - {lock.LOCK}:
        why = "a new or empty directory (--resume continues the figure in it, --replot redraws it)"
        raise InvalidConfig("out", out, why)
    check(not os.path.exists(out) or os.path.isdir(out), "out", out, "a directory, not a file")
    loop.check_writable(out)
