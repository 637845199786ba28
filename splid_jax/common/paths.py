"""Why a path cannot be read: a file behind a directory without permission is no missing file."""

from __future__ import annotations

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
