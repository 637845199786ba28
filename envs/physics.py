"""Which code computes a task's MJX physics: ``mjx`` calls MJX as the library it is; ``kernels`` runs MJX with
parts of its step replaced by this package's faster equivalents (``envs/mjx_patch.py``).

The replacements reach into MJX's private functions, which any release may change, so they run only on the
MuJoCo version they were checked against (``KERNELS_CHECKED``; the check: ``experiments/physics_equality.py``
on a GPU, ``tests/envs`` on a CPU). On any other a task asked for ``kernels`` runs stock MJX and says so once,
in one line on stderr."""

from __future__ import annotations

import functools
import importlib.metadata
import sys

KERNELS_CHECKED = "3.17.0"  # the mujoco and mujoco-mjx release the kernels were checked against
BACKENDS = ("kernels", "mjx")


def installed() -> tuple[str, str]:
    """(mujoco, mujoco-mjx) versions as installed."""
    import mujoco

    try:
        mjx = importlib.metadata.version("mujoco-mjx")
    except importlib.metadata.PackageNotFoundError:  # MJX shipped inside mujoco
        mjx = mujoco.__version__
    return mujoco.__version__, mjx


def kernels_checked() -> bool:
    """Whether the installed MuJoCo is the release the kernels were checked against."""
    return all(v == KERNELS_CHECKED for v in installed())


def in_use(choice: str) -> str:
    """The backend a task set to ``choice`` runs: ``kernels`` only on the checked MuJoCo version."""
    if choice != "kernels" or kernels_checked():
        return choice
    _notice(installed(), KERNELS_CHECKED)
    return "mjx"


@functools.cache
def _notice(versions: tuple[str, str], checked: str) -> None:
    print(
        f"note: physics=kernels runs as physics=mjx (stock MJX): mujoco {versions[0]}, mujoco-mjx {versions[1]} "
        f"installed, the kernels were checked on {checked}",
        file=sys.stderr,
    )
