"""The statistics of episodes: Wilson intervals and the summary of success and final distance."""

import pytest

pytest.importorskip("gymnasium_robotics")

from splid_jax.reference import episodes  # noqa: E402


def test_wilson_interval():
    lo, hi = episodes.wilson(0, 10)
    assert lo == 0.0 and hi == pytest.approx(0.2775, abs=1e-4)
    lo, hi = episodes.wilson(10, 10)
    assert hi == 1.0 and lo == pytest.approx(0.7225, abs=1e-4)
    lo, hi = episodes.wilson(210, 300)  # p = 0.7
    assert lo == pytest.approx(0.6463, abs=1e-3) and hi == pytest.approx(0.7487, abs=1e-3)


def test_summarise():
    s = episodes.summarise([1, 1, 0, 1], [1, 0, 0, 1], [0.01, 0.1, 0.2, 0.03])
    assert s["episodes"] == 4 and s["success_any"] == 0.75 and s["success_final"] == 0.5
    assert s["median_final_distance"] == pytest.approx(0.065)
    assert s["success_final_ci95"][0] < 0.5 < s["success_final_ci95"][1]
