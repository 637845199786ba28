"""The one way a config dataclass declares a field: its default and the one line ``--help`` shows."""

from __future__ import annotations

import dataclasses


def field(default, help: str, **metadata):
    return dataclasses.field(default=default, metadata={"help": help, **metadata})
