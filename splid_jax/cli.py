"""Command lines generated from frozen config dataclasses, so ``--help`` documents every field."""

from __future__ import annotations

import argparse
import dataclasses
import os

import jax


def _int_tuple(text: str) -> tuple[int, ...]:
    try:
        return tuple(int(w) for w in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected comma-separated integers, got {text!r}") from None


_TYPES = {"int": int, "float": float, "str": str, "str | None": str, "tuple[int, ...]": _int_tuple}


def add_config_flags(
    parser: argparse.ArgumentParser, cls, per_task: dict[str, dict] | None = None, exclude: frozenset[str] = frozenset()
) -> None:
    """One flag per field (less ``exclude``); every default is None so that explicit values can be told apart."""
    for f in dataclasses.fields(cls):
        if f.name in exclude:
            continue
        flag = "--" + f.name.replace("_", "-")
        help_text = f.metadata.get("help", "")
        if f.default is not None:
            help_text += f" (default: {f.default})"
        elif per_task and any(f.name in d for d in per_task.values()):
            shown = ", ".join(f"{task} {_show(d[f.name])}" for task, d in per_task.items() if f.name in d)
            help_text += f" (default per task: {shown})"
        if f.type == "bool":
            parser.add_argument(flag, action=argparse.BooleanOptionalAction, default=None, help=help_text)
        else:
            parser.add_argument(flag, type=_TYPES[f.type], default=None, help=help_text, metavar=f.name.upper())


def _show(value) -> str:
    return ",".join(map(str, value)) if isinstance(value, tuple) else str(value)


def explicit_values(cls, namespace: argparse.Namespace) -> dict:
    names = {f.name for f in dataclasses.fields(cls)}
    return {k: v for k, v in vars(namespace).items() if k in names and v is not None}


def default_compile_cache() -> str:
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return os.path.join(base, "splid_jax", "jax")


def add_compile_cache_flag(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--compile-cache",
        metavar="DIR",
        default=default_compile_cache(),
        help="keep compiled programs in DIR, so a rerun with the same task and shapes skips most of "
        "its compilation ('' turns it off; default: %(default)s)",
    )


def use_compile_cache(path: str) -> None:
    """JAX's persistent compilation cache: MJX programs take tens of seconds to compile and are
    the same from one run of a setting to the next."""
    if path:  # programs that compile in under a second are not kept (JAX's default threshold)
        jax.config.update("jax_compilation_cache_dir", path)
