"""The figures package: every name it offers is the function, class or constant its module defines,
and importing it loads no JAX, so that ``python -m splid_jax.figures`` sets its signal handlers first."""

import importlib
import os
import subprocess
import sys
import types

import pytest

from splid_jax import figures

MODULES = ("registry", "settings", "planning", "record", "runs", "merging", "series", "table", "drawing", "cli")


def test_every_offered_name_is_its_modules_not_a_submodule():
    for name in MODULES:  # a submodule named like an offered name would replace it once imported
        importlib.import_module(f"splid_jax.figures.{name}")
    for name in figures.__all__:
        value = getattr(figures, name)
        assert not isinstance(value, types.ModuleType), name
    assert figures.plan is figures.planning.plan and figures.main is figures.cli.main


def test_an_unknown_name_is_an_attribute_error():
    with pytest.raises(AttributeError, match="no_such_name"):
        figures.no_such_name  # noqa: B018


@pytest.mark.slow
def test_importing_the_package_loads_no_jax():
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
    code = "import sys, splid_jax.figures; print(sorted(m for m in ('jax', 'matplotlib') if m in sys.modules))"
    env = {**os.environ, "PYTHONPATH": root}
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True)
    assert done.stdout.strip() == "[]"
