"""The command line's figure settings as values: ``--methods``, ``--values`` and ``--set
[METHOD.]FIELD=VALUE``, each refused in one line when it names what the figure cannot train."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from splid_jax.common.errors import InvalidConfig, check
from splid_jax.common.values import read_value, typed_value
from splid_jax.config import TrainConfig
from splid_jax.figures.registry import METHODS, SHORT, Spec
from splid_jax.learners import registry as learners

# Set by the figure itself, not through --set.
OWNED = frozenset({"env", "algo", "select", "seed", "iterations", "run_dir"})


def reads(algo: str, field: str) -> bool:
    """Whether ``algo`` reads a TrainConfig field, so that a setting given for every method skips
    those that do not (ES's num_envs is its population's episodes)."""
    return learners.reads(algo, field)


def parse_methods(text: str, allowed: Sequence[str]) -> tuple[str, ...]:
    words = tuple(w.strip() for w in text.split(","))
    bad = [w for w in words if w not in allowed]
    check(
        not bad and len(set(words)) == len(words) and words != ("",),
        "methods",
        text,
        "distinct names among " + ", ".join(allowed),
    )
    return words


def parse_sets(items: Sequence[str], methods: Sequence[str]) -> dict[str | None, dict[str, Any]]:
    """``[METHOD.]FIELD=VALUE`` items as {None: fields for every method, METHOD: its own fields}."""
    types = {f.name: f.type for f in TrainConfig.settings_fields()}
    out: dict[str | None, dict[str, Any]] = {None: {}}
    for item in items:
        key, eq, value = item.partition("=")
        method, dot, name = key.rpartition(".")
        name = name.replace("-", "_")
        if not eq or (dot and method not in methods):
            allowed = "[METHOD.]FIELD=VALUE with METHOD among " + ", ".join(methods) if methods else "FIELD=VALUE"
            raise InvalidConfig("set", item, allowed)
        check(
            name in types and name not in OWNED,
            "set",
            item,
            "a TrainConfig field other than " + ", ".join(sorted(OWNED)) + " (see python -m splid_jax.train --help)",
        )
        algo = METHODS[method].fields["algo"] if method else None
        check(not algo or reads(algo, name), "set", item, f"a field that {method} reads")
        kind = str(types[name])
        if kind.startswith("tuple"):  # one field per --set, so its commas are the tuple's
            value = value.replace(",", ":")
        elif kind != "str":
            value = read_value(value)
        try:
            out.setdefault(method or None, {})[name] = typed_value(name, kind, value)
        except InvalidConfig as err:  # named as typed: the --set item, not the field alone
            raise InvalidConfig("set", item, err.allowed) from None
    return out


def parse_values(spec: Spec, text: str | None) -> tuple:
    """``--values``: the swept field's values, as integers for H and floats for sigma."""
    if text is None:
        return ()
    check(spec.vary is not None, "values", text, "given only for fig4 (H) or fig5 (sigma)")
    kind = int if spec.vary == "horizon" else float
    try:
        values = tuple(kind(w) for w in text.split(","))
    except ValueError:
        raise InvalidConfig("values", text, f"comma-separated {SHORT[spec.vary]} values") from None
    check(len(set(values)) == len(values), "values", text, "distinct values")
    return values
