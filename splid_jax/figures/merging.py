"""One figure directory joined from parts of a figure trained apart (other machines, calls or processes)."""

from __future__ import annotations

import os
import shutil
from collections.abc import Sequence

from splid_jax.common.errors import check
from splid_jax.figures.record import SPEC, check_out, load_record
from splid_jax.figures.registry import SHORT, SPECS
from splid_jax.runtime import loop


def merge(out: str, parts: Sequence[str], figure: str, command: str) -> dict:
    """One figure from parts of it trained apart (other machines, calls or processes): Figure 3's
    ``--methods`` subsets, or Figure 4's or 5's ``--values`` subsets, each then a sweep of its own
    shapes (an H sweep replays every member at its largest H's cost). Each part's method directories are
    copied into ``out`` (checkpoints too, so ``--resume`` continues an unfinished one) and their records
    joined; the parts stay as they are."""
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
        check(len(set(methods)) == len(methods), "merge", joined, "directories that train distinct methods")
    check_out(out)
    os.makedirs(out, exist_ok=True)
    runs: dict[str, dict] = {}
    for i, (part, record) in enumerate(zip(parts, records, strict=True)):
        for method in record["methods"]:
            sub = [f"part{i}"] if spec.vary else []
            if os.path.isdir(os.path.join(part, method)):
                shutil.copytree(os.path.join(part, method), os.path.join(out, method, *sub))
            if spec.vary:
                runs.setdefault(method, {"parts": []})["parts"].append({**record["runs"][method], "dir": sub[0]})
            else:
                runs[method] = record["runs"][method]
    merged = {
        **first,
        "methods": sorted(set(methods), key=spec.methods.index),
        "device": " + ".join(dict.fromkeys(r["device"] for r in records)),
        "date": " + ".join(dict.fromkeys(r["date"] for r in records)),
        "command": command,
        "runs": runs,
        "parts": [{k: r[k] for k in ("command", "device", "date", "methods")} for r in records],
    }
    loop.write_json(os.path.join(out, SPEC), merged)
    return merged
