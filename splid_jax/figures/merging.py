"""One figure directory joined from parts of a figure trained apart (other machines, calls or processes)."""

from __future__ import annotations

import os
import shutil
from collections.abc import Sequence

from splid_jax.common.errors import check
from splid_jax.figures.record import SPEC, check_out, load_record
from splid_jax.figures.registry import METHODS, SHORT, SPECS
from splid_jax.runtime import loop


def merge(out: str, parts: Sequence[str], figure: str, command: str, replace: bool = False) -> dict:
    """One figure from parts of it trained apart (other machines, calls or processes): Figure 3's
    ``--methods`` subsets, or Figure 4's or 5's ``--values`` subsets, each then a sweep of its own
    shapes (an H sweep replays every member at its largest H's cost). Each part's method directories are
    copied into ``out`` (checkpoints too, so ``--resume`` continues an unfinished one) and their records
    joined; the parts stay as they are. A Figure 3 part may itself be merged: its parts' commands carry
    over. With ``replace`` a method in several parts is taken from the last, so a method run again
    replaces its earlier run."""
    check(len(parts) >= 2, "merge", " ".join(parts), "two or more figure directories")
    records = [load_record(p, "merge") for p in parts]
    first, spec = records[0], SPECS[figure]
    check(first["figure"] == figure, "merge", parts[0], f"a {figure} directory")
    for part, record in zip(parts, records, strict=True):
        for key in ("figure", "env", "seeds", "budget_episodes"):
            check(
                record.get(key) == first.get(key),
                "merge",
                part,
                f"a figure directory with the {key} of {parts[0]} ({first.get(key)!r})",
            )
        merged_before = any("parts" in ran for ran in record["runs"].values())
        check(not merged_before, "merge", part, "a figure directory one command trained, not a merged one")
    joined = " ".join(parts)
    if spec.vary:
        values = [m[spec.vary] for r in records for ran in r["runs"].values() for m in ran["members"]]
        distinct = len(set(values)) * first["seeds"] == len(values)
        check(distinct, "merge", joined, f"directories that train distinct {SHORT[spec.vary]} values")
        methods = list(spec.methods)
    else:
        methods = [m for r in records for m in r["methods"]]
        distinct = len(set(methods)) == len(methods) or replace
        check(distinct, "merge", joined, "directories that train distinct methods (--replace: the last part's run)")
    check(not (replace and spec.vary), "replace", True, "given with fig3's --merge (methods, not values)")
    # the part each method is taken from: the last that has it
    source = {m: i for i, r in enumerate(records) for m in r["methods"]}
    check_out(out)
    os.makedirs(out, exist_ok=True)
    runs: dict[str, dict] = {}
    commands: list[dict] = []
    for i, (part, record) in enumerate(zip(parts, records, strict=True)):
        taken = [m for m in record["methods"] if spec.vary or source[m] == i]
        for method in taken:
            sub = [f"part{i}"] if spec.vary else []
            if os.path.isdir(os.path.join(part, method)):
                shutil.copytree(os.path.join(part, method), os.path.join(out, method, *sub))
            if spec.vary:
                runs.setdefault(method, {"parts": []})["parts"].append({**record["runs"][method], "dir": sub[0]})
            else:
                runs[method] = record["runs"][method]
        own = record.get("parts") or [{k: record[k] for k in ("command", "device", "date", "methods")}]
        for entry in own:  # a merged part's own parts, less the methods a later part replaces
            kept = [m for m in entry["methods"] if m in taken]
            if kept:
                commands.append({**entry, "methods": kept})
    merged = {
        **first,
        "methods": sorted(set(methods), key=list(METHODS).index),  # the legend order, her-baselines too
        "device": " + ".join(dict.fromkeys(c["device"] for c in commands)),
        "date": " + ".join(dict.fromkeys(c["date"] for c in commands)),
        "command": command,
        "runs": runs,
        "parts": commands,
    }
    loop.write_json(os.path.join(out, SPEC), merged)
    return merged
