"""The one error a mistake in a setting raises, wherever it is checked (the command line, a config,
a task's fields): the tasks' own (``envs/settings.py``), so that a task's check and the trainer's are
caught as one and turned into one line and exit code 2."""

from __future__ import annotations

from envs.settings import InvalidConfig, check, check_integer

__all__ = ["InvalidConfig", "check", "check_integer"]
