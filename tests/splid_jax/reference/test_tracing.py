"""The observation slots compared one by one between the two simulators."""

import numpy as np
import pytest

pytest.importorskip("gymnasium_robotics")

from splid_jax.reference import tracing  # noqa: E402


def test_compare_slots_names_each_slot():
    ours = np.zeros((2, 3, 25))
    fetch = ours.copy()
    fetch[:, :, 13] = 0.5  # the object's yaw
    got = tracing.compare_slots(ours, fetch)
    assert list(got)[13] == "euler c" and len(got) == 25
    assert got["euler c"] == {"ours": 0.0, "fetch": 0.5, "diff": 0.5, "start_diff": 0.5}
    assert got["grip x"]["diff"] == 0.0
