"""Statistics over runs at the evaluations they all reached: the mean, the standard error of the
mean and the min-max band that ``plot --group`` and the figures draw, computed in one place so that
both show the same numbers for the same runs."""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence

import numpy as np

Columns = Mapping[str, np.ndarray]  # one run's values per evaluation by name, "iteration" among them


def common_iterations(members: Sequence[Columns]) -> list:
    """The iterations every member evaluated, ascending, so that a mean never mixes in fewer runs."""
    return sorted(set.intersection(*(set(m["iteration"].tolist()) for m in members)))


def aligned(members: Sequence[Columns], keys: Iterable[str], common: Sequence) -> dict[str, np.ndarray]:
    """Each key's values at the ``common`` iterations, one row per member (members sorted by iteration)."""
    at = [np.searchsorted(m["iteration"], common) for m in members]
    return {k: np.stack([m[k][i] for m, i in zip(members, at, strict=True)]) for k in keys}


def mean(rows: np.ndarray) -> np.ndarray:
    """The mean over members (rows) at each evaluation."""
    return rows.mean(0)


def sem(rows: np.ndarray) -> np.ndarray:
    """The standard error of the mean over members (rows): nan for a single member, which has no spread."""
    n = len(rows)
    return rows.std(0, ddof=1) / math.sqrt(n) if n > 1 else np.full(rows.shape[1], np.nan)


def band(rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The lowest and highest value over members (rows) at each evaluation."""
    return rows.min(0), rows.max(0)


def smooth(y: np.ndarray, k: int) -> np.ndarray:
    """Trailing mean over the last ``k`` evaluations (fewer at the start), so no point sees the future."""
    if k <= 1:
        return y
    c = np.cumsum(np.insert(y, 0, 0.0))
    i = np.arange(1, len(y) + 1)
    lo = np.maximum(i - k, 0)
    return (c[i] - c[lo]) / (i - lo)
