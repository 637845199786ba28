"""Shared by the env tests: which primitives a traced program holds, nested jaxprs included."""

import jax
import jax.extend.core
import pytest


def _primitives(jaxpr) -> set[str]:
    names = set()
    for eqn in jaxpr.eqns:
        names.add(eqn.primitive.name)
        for sub in jax.extend.core.jaxprs_in_params(eqn.params):
            names |= _primitives(sub)
    return names


@pytest.fixture
def primitives():
    """``primitives(fn, *args)``: the names of the primitives in ``fn``'s jaxpr at ``args``."""
    return lambda fn, *args: _primitives(jax.make_jaxpr(fn)(*args).jaxpr)
