"""The reference package: every name it offers is the one its modules define (never a submodule that
shadows it once loaded), so code written against ``splid_jax.reference.NAME`` keeps working."""

import importlib
import types

from splid_jax import reference

MODULES = ("extra", "mapping", "episodes", "tracing", "response", "policy", "cli")


def test_every_offered_name_is_its_modules_own():
    modules = [importlib.import_module(f"splid_jax.reference.{m}") for m in MODULES]
    for name in reference.__all__:
        obj = getattr(reference, name)
        assert not isinstance(obj, types.ModuleType), name
        assert any(getattr(m, name, None) is obj for m in modules), name
    assert "main" in dir(reference)
