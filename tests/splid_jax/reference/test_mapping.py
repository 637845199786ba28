"""Matched starts handed to another interpreter: the starts file and the episodes file come back as written."""

import numpy as np
import pytest

pytest.importorskip("gymnasium_robotics")

from splid_jax.reference import episodes, mapping  # noqa: E402


def test_starts_round_trip_with_and_without_an_object(tmp_path):
    goal = np.arange(6.0).reshape(2, 3)
    mapping.save_starts(tmp_path / "a.npz", {"state": object(), "object_xy": goal[:, :2] + 0.5, "goal": goal})
    got = mapping.load_starts(tmp_path / "a.npz")
    np.testing.assert_array_equal(got["goal"], goal)
    np.testing.assert_array_equal(got["object_xy"], goal[:, :2] + 0.5)
    mapping.save_starts(tmp_path / "b.npz", {"object_xy": None, "goal": goal})  # Reach
    assert mapping.load_starts(tmp_path / "b.npz")["object_xy"] is None


def test_episodes_round_trip(tmp_path):
    rng = np.random.default_rng(0)
    ep = episodes.Episodes(obs=rng.normal(size=(2, 4, 25)), achieved=rng.normal(size=(2, 4, 3)),
                           goal=rng.normal(size=(2, 3)), success=rng.normal(size=(2, 3)) > 0,
                           actions=rng.normal(size=(2, 3, 4)), dt=0.04)  # fmt: skip
    ep.save(tmp_path / "e.npz")
    got = episodes.Episodes.load(tmp_path / "e.npz")
    assert got.dt == 0.04 and got.success.dtype == bool
    for k in ("obs", "achieved", "goal", "success", "actions"):
        np.testing.assert_array_equal(getattr(got, k), getattr(ep, k))
    assert got.summary() == ep.summary()
