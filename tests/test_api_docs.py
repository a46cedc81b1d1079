"""Every Python example of docs/api.md runs as written: each block as a script, in order, in
one fresh folder (later blocks use what earlier ones wrote), as a reader would run them."""

import ast
import importlib
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

import poro2d

DOC = Path(__file__).resolve().parents[1] / "docs" / "api.md"
BLOCK = re.compile(r"^```python\n(.*?)^```", re.MULTILINE | re.DOTALL)


def python_blocks(text: str) -> list[str]:
    return BLOCK.findall(text)


def test_the_block_pattern_finds_python_only():
    text = "x\n```python\na = 1\n```\n```bash\nls\n```\n```python\nb = 2\n```\n"
    assert python_blocks(text) == ["a = 1\n", "b = 2\n"]


def deep_imports(code: str) -> list[str]:
    """``module.name`` of every ``from poro2d.<module> import name`` in ``code`` whose name the
    package itself gives (:data:`poro2d.PUBLIC`) as the same object."""
    found = []
    for node in ast.walk(ast.parse(code)):
        if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("poro2d."):
            for alias in node.names:
                public = poro2d.PUBLIC.get(alias.name)
                if public is not None and getattr(poro2d, alias.name) is getattr(
                    importlib.import_module(node.module), alias.name, None
                ):
                    found.append(f"{node.module}.{alias.name}")
    return found


def test_examples_import_from_the_package_where_it_gives_the_name():
    """A reader imports `from poro2d import Store`, not from the module three levels down."""
    deep = [name for code in python_blocks(DOC.read_text()) for name in deep_imports(code)]
    assert deep == []
    assert deep_imports("from poro2d.store import Store\nfrom poro2d.locks import cache_entry\n") == [
        "poro2d.store.Store"
    ]


def test_export_is_on_the_page():
    code = "\n".join(python_blocks(DOC.read_text()))
    for name in ("export_specimen", "export_lammps", "export_yade", "export_csv"):
        assert re.search(rf"^from poro2d import .*\b{name}\b", code, re.MULTILINE), name


@pytest.mark.scenario  # the examples run a quick paper case and a quick relation
def test_every_example_runs(tmp_path):
    blocks = python_blocks(DOC.read_text())
    assert len(blocks) >= 5
    env = dict(os.environ)
    # this checkout's poro2d, whatever is installed; calibrations cached here, not for the user
    env["PYTHONPATH"] = os.pathsep.join([str(Path(poro2d.__file__).parents[1]), env.get("PYTHONPATH", "")])
    env["PORO2D_CACHE"] = str(tmp_path / "cache")
    env["MPLBACKEND"] = "Agg"
    work = tmp_path / "work"
    work.mkdir()
    for k, code in enumerate(blocks):
        script = work / f"example_{k}.py"
        script.write_text(code)
        run = subprocess.run([sys.executable, script.name], cwd=work, env=env, capture_output=True, text=True)
        assert run.returncode == 0, f"example {k} of {DOC.name} failed:\n{code}\n{run.stderr[-3000:]}"
        assert run.stdout.strip(), f"example {k} printed nothing"
    for f in ("crit/specimen.npz", "shear/result.json", "biaxial/result.json", "paper-out/report.html",
              "relation-out/relation.png", "lmp/specimen.data", "lmp/in.specimen", "yade/specimen_yade.py",
              "csv/disks.csv"):  # fmt: skip
        assert (work / f).stat().st_size > 0, f
