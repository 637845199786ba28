"""Paths a command is about to use: why one cannot be read (a file behind a directory without
permission is no missing file), and which directories making one would create."""

from __future__ import annotations

import contextlib
import os


def unreadable(path: str) -> str | None:
    """The reason ``path`` exists but cannot be read, or None (readable, or simply absent)."""
    try:
        os.stat(path)
    except FileNotFoundError:
        return None
    except OSError as e:  # a directory on the way that may not be searched
        return e.strerror
    want = os.R_OK | (os.X_OK if os.path.isdir(path) else 0)
    return None if os.access(path, want) else "Permission denied"


def is_utf8(path: str) -> bool:
    """Whether ``path`` is UTF-8 text: a name with other bytes (``\\xff``) cannot reach orbax's and
    TensorStore's C++ code, which takes UTF-8 strings."""
    try:
        path.encode("utf-8")
    except UnicodeEncodeError:
        return False
    return True


def missing_parents(path: str) -> list[str]:
    """The directories ``os.makedirs(path)`` would create, deepest first: what to remove again when
    the work they were made for does not happen."""
    made, path = [], os.path.abspath(path)
    while not os.path.exists(path):
        made.append(path)
        path = os.path.dirname(path)
    return made


def unwritable(path: str) -> str | None:
    """Why files cannot be written in directory ``path`` (made for the probe if missing, then removed
    again), or None: a read-only filesystem, /proc or a regular file fails here, before any work."""
    made = missing_parents(path)
    try:
        for d in reversed(made):
            os.mkdir(d)
        probe = os.path.join(path, f".write-test-{os.getpid()}")
        with open(probe, "w") as fh:
            fh.write("x")
        os.remove(probe)
    except OSError as e:
        return e.strerror or str(e)
    finally:
        for d in made:
            with contextlib.suppress(OSError):
                os.rmdir(d)
    return None
