"""The statistics plot --group and the figures share, against values worked out by hand."""

import math

import numpy as np

from splid_jax.common import stats


def _run(iterations, values):
    return {"iteration": np.asarray(iterations, float), "x": np.asarray(values, float)}


def test_members_are_compared_at_the_evaluations_they_all_reached():
    a, b = _run([1, 2, 3], [10, 20, 30]), _run([2, 3, 4], [1, 2, 3])
    common = stats.common_iterations([a, b])
    assert common == [2.0, 3.0]
    rows = stats.aligned([a, b], ("x", "iteration"), common)
    np.testing.assert_array_equal(rows["x"], [[20, 30], [1, 2]])
    np.testing.assert_array_equal(rows["iteration"], [[2, 3], [2, 3]])


def test_no_common_evaluation_gives_no_iterations():
    assert stats.common_iterations([_run([1], [0]), _run([2], [0])]) == []


def test_mean_standard_error_and_band_over_members():
    rows = np.asarray([[1.0, 3.0], [3.0, 7.0], [5.0, 5.0]])
    np.testing.assert_array_equal(stats.mean(rows), [3.0, 5.0])
    # sample standard deviations 2 and 2, over sqrt(3) members
    np.testing.assert_allclose(stats.sem(rows), [2 / math.sqrt(3), 2 / math.sqrt(3)], rtol=1e-15)
    low, high = stats.band(rows)
    np.testing.assert_array_equal(low, [1.0, 3.0])
    np.testing.assert_array_equal(high, [5.0, 7.0])


def test_one_member_has_no_standard_error():
    sem = stats.sem(np.asarray([[0.5, 0.25, 1.0]]))
    assert sem.shape == (3,) and np.isnan(sem).all()


def test_trailing_mean_never_sees_later_evaluations():
    y = np.asarray([1.0, 2.0, 3.0, 4.0])
    np.testing.assert_allclose(stats.smooth(y, 2), [1.0, 1.5, 2.5, 3.5])
    np.testing.assert_allclose(stats.smooth(y, 3), [1.0, 1.5, 2.0, 3.0])
    assert stats.smooth(y, 1) is y
