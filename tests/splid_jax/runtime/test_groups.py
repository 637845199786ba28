"""The devices' programs of a split sweep are called at once, one thread each (the whole split sweep:
test_devices.py)."""

import threading

import pytest

from splid_jax.runtime.groups import _at_once


def test_calls_run_at_once_and_return_in_order():
    met = threading.Barrier(3, timeout=10)  # each call waits for the others: calls in turn would break it

    def call(i):
        met.wait()
        return i

    assert _at_once([lambda i=i: call(i) for i in range(3)]) == [0, 1, 2]


def test_an_error_in_any_call_is_raised_after_all_end():
    ended = []

    def bad():
        raise ValueError("device 1")

    def slow():
        ended.append(True)
        return 0

    with pytest.raises(ValueError, match="device 1"):
        _at_once([slow, bad, slow])
    assert ended == [True, True]
