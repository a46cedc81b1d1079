"""The short public API at the top level: each name is its module's own object; ``import poro2d`` is light."""

from __future__ import annotations

import importlib
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

import poro2d

SRC = Path(__file__).resolve().parents[1] / "src"


@pytest.mark.parametrize("name", sorted(poro2d.PUBLIC))
def test_name_is_the_deep_object(name):
    module, attr = poro2d.PUBLIC[name]
    assert getattr(poro2d, name) is getattr(importlib.import_module(module), attr)
    assert name in poro2d.__all__
    assert name in dir(poro2d)


def test_unknown_name_is_an_attribute_error():
    with pytest.raises(AttributeError, match="no_such_name"):
        poro2d.no_such_name  # noqa: B018
    from poro2d import porosity  # a submodule still imports as one

    assert porosity.parabolic is poro2d.parabolic


def test_import_is_light():
    """A fresh ``import poro2d`` loads no numba, numpy or submodule of poro2d."""
    code = "import json, sys, poro2d; print(json.dumps(sorted(sys.modules)))"
    env = {**os.environ, "PYTHONPATH": str(SRC) + os.pathsep + os.environ.get("PYTHONPATH", "")}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True)
    loaded = json.loads(out.stdout)
    heavy = [m for m in loaded if m.split(".")[0] in {"numba", "numpy", "llvmlite", "dask", "matplotlib"}]
    assert heavy == []
    assert [m for m in loaded if m.startswith("poro2d.")] == []


def test_no_name_is_a_submodule():
    """A submodule, once imported, would replace a top-level name of the same spelling."""
    submodules = {p.stem if p.suffix == ".py" else p.name for p in (SRC / "poro2d").iterdir()}
    assert sorted(set(poro2d.PUBLIC) & submodules) == []
