"""The package's structure as ARCHITECTURE.md draws it: floors, no circles, no private reads.

The floors table of ARCHITECTURE.md is parsed here and every import in ``src/poro2d`` (at
module level, inside functions, under ``TYPE_CHECKING``) is checked against it, so the
document cannot drift from the code.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SRC = ROOT / "src"
PACKAGE = SRC / "poro2d"

#: private names an object may read from another object of the same class in the same module
SAME_CLASS_READS = {("typed_result.py", "obj._absent")}


def _modules() -> dict[str, Path]:
    out = {}
    for p in sorted(PACKAGE.rglob("*.py")):
        parts = list(p.relative_to(SRC).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = p
    return out


def _imports(name: str, path: Path, modules: dict[str, Path]) -> set[str]:
    """The poro2d modules ``name`` imports anywhere in its file."""
    found = set()
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join(anchor + ([base] if base else []))
            # a name that is a submodule imports that module; any other name, the module `base`
            targets = [f"{base}.{a.name}" if f"{base}.{a.name}" in modules else base for a in node.names]
        else:
            continue
        for t in targets:
            # "from poro2d.dem import Simulation" names the package; "import poro2d.dem.state" the module
            while t and t not in modules:
                t = t.rpartition(".")[0]
            if t and t != name and t != "poro2d":
                found.add(t)
    return found


def _floors() -> dict[str, int]:
    """Path prefix (relative to src/) -> floor, from the table of ARCHITECTURE.md."""
    text = (ROOT / "ARCHITECTURE.md").read_text()
    floors = {}
    for line in text.splitlines():
        m = re.match(r"\|\s*(\d+)\s*\|[^|]*\|([^|]*)\|", line)
        if m:
            for path in re.findall(r"`src/([^`]+)`", m.group(2)):
                floors[path] = int(m.group(1))
    return floors


def _floor_of(path: Path, floors: dict[str, int]) -> int | None:
    rel = path.relative_to(SRC).as_posix()
    best = [(len(k), v) for k, v in floors.items() if rel == k or (k.endswith("/") and rel.startswith(k))]
    return max(best)[1] if best else None


@pytest.fixture(scope="module")
def graph():
    modules = _modules()
    return modules, {m: _imports(m, p, modules) for m, p in modules.items()}


def test_the_floors_table_places_every_module(graph):
    modules, _ = graph
    floors = _floors()
    assert len(set(floors.values())) >= 8, "the floors table of ARCHITECTURE.md was not found"
    unplaced = [m for m, p in modules.items() if _floor_of(p, floors) is None]
    assert not unplaced, f"modules in no floor of ARCHITECTURE.md: {unplaced}"


def test_no_import_runs_up_a_floor(graph):
    modules, imports = graph
    floors = _floors()
    up = [
        f"{m} (floor {_floor_of(modules[m], floors)}) -> {t} (floor {_floor_of(modules[t], floors)})"
        for m, targets in imports.items()
        for t in targets
        if _floor_of(modules[t], floors) > _floor_of(modules[m], floors)
    ]
    assert not up, "imports that run up a floor:\n" + "\n".join(sorted(up))


def _circle(imports: dict[str, set[str]]) -> list[str] | None:
    """One import circle among modules, or None. A package's face (__init__) re-exports its
    modules, and they import siblings by the package's name: such edges are read through."""
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(m: str) -> list[str] | None:
        state[m] = 1
        stack.append(m)
        for t in sorted(imports.get(m, ())):
            if t.startswith(m + "."):  # a package's face importing its own modules
                continue
            if state.get(t) == 1:
                return stack[stack.index(t) :] + [t]
            if t not in state and (found := visit(t)):
                return found
        stack.pop()
        state[m] = 2
        return None

    for m in sorted(imports):
        if m not in state and (found := visit(m)):
            return found
    return None


def _without_faces(modules: dict[str, Path], imports: dict[str, set[str]]) -> dict[str, set[str]]:
    """Imports of a package's face replaced by what the face itself imports from its package."""
    faces = {m for m, p in modules.items() if p.name == "__init__.py"}
    out = {}
    for m, targets in imports.items():
        if m in faces:
            continue
        resolved = set()
        for t in targets:
            resolved |= {x for x in imports[t] if x.startswith(t + ".")} if t in faces else {t}
        out[m] = resolved - {m}
    return out


def test_no_import_circle(graph):
    modules, imports = graph
    circle = _circle(_without_faces(modules, imports))
    assert circle is None, "import circle: " + " -> ".join(circle)


def test_the_circle_finder_finds_a_circle():
    assert _circle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]
    assert _circle({"a": {"b"}, "b": set()}) is None


def _private_reads(path: Path, root: Path = SRC) -> list[str]:
    """``x._name`` where x is not self/cls, and ``from poro2d... import _name``."""
    tree = ast.parse(path.read_text())
    found = []
    for node in ast.walk(tree):
        private = isinstance(node, ast.Attribute) and re.match(r"_[a-zA-Z]", node.attr)
        if private and not node.attr.startswith("__"):
            base = node.value
            if isinstance(base, ast.Name) and base.id in ("self", "cls"):
                continue
            text = ast.unparse(node)
            allowed = (path.name, text) in SAME_CLASS_READS or text.startswith(("os._exit", "sys._getframe"))
            if not allowed:
                found.append(f"{path.relative_to(root)}:{node.lineno}: {text}")
        elif isinstance(node, ast.ImportFrom) and (node.module or "").startswith("poro2d"):
            found += [
                f"{path.relative_to(root)}:{node.lineno}: import {a.name}"
                for a in node.names
                if a.name.startswith("_") and not a.name.startswith("__")
            ]
    return found


def test_no_module_reads_another_modules_private_names(graph):
    modules, _ = graph
    reads = [r for p in modules.values() for r in _private_reads(p)]
    assert not reads, "private names read across objects:\n" + "\n".join(reads)


def test_the_private_read_scan_sees_one(tmp_path):
    probe = tmp_path / "probe.py"
    probe.write_text("from poro2d.x import _hidden\n\ndef f(sim):\n    return sim._pairs, self._own\n")
    assert _private_reads(probe, tmp_path) == ["probe.py:1: import _hidden", "probe.py:4: sim._pairs"]


#: where files may be read and written: the store, the engine's own checkpoints and VTU,
#: the ground floor's atomic writers, input readers and locks, the report's figures and
#: documents, the writers and readers of other codes' formats, the package's data files
FILE_HOMES = (
    "store/",
    "dem/",
    "io_utils.py",
    "locks.py",
    "config.py",
    "report/figure_file.py",
    "report/document.py",
    "interop/lammps.py",
    "interop/lammps_run.py",
    "interop/yade.py",
    "interop/pfc.py",
    "interop/csv_table.py",
    "interop/validate.py",
    "grading.py",
)

#: calls that read or write files: (owner or "" for a bare name, function)
_FILE_CALLS = {
    ("", "write_json"), ("", "write_csv"), ("", "atomic_path"), ("", "open"),
    ("np", "savez"), ("np", "savez_compressed"), ("np", "load"), ("pd", "read_csv"),
    ("json", "loads"), ("json", "load"), ("json", "dump"),
    ("checkpoint", "save"), ("checkpoint", "load"), ("checkpoint", "read"), ("checkpoint", "read_meta"),
    ("shutil", "copyfile"), ("shutil", "copy2"), ("shutil", "copytree"),
    ("*", "to_csv"), ("*", "read_text"), ("*", "write_text"),
}  # fmt: skip


def _file_calls(path: Path) -> list[str]:
    calls = []
    for node in ast.walk(ast.parse(path.read_text())):
        if not isinstance(node, ast.Call):
            continue
        f = node.func
        if isinstance(f, ast.Name):
            key = ("", f.id)
        elif isinstance(f, ast.Attribute):
            owner = ast.unparse(f.value)
            if "store" in owner.lower():  # a store's own method (store.write_text, Store(root).read_text)
                continue
            key = (owner, f.attr) if (owner, f.attr) in _FILE_CALLS else ("*", f.attr)
        else:
            continue
        if key in _FILE_CALLS:
            calls.append(f"{node.lineno}: {ast.unparse(f)}")
    return calls


def test_result_files_are_read_and_written_by_the_store_only():
    """One module family reads and writes result files: protocols are handed a Store."""
    found = {}
    for p in sorted(PACKAGE.rglob("*.py")):
        rel = p.relative_to(PACKAGE).as_posix()
        if rel.startswith(FILE_HOMES):
            continue
        calls = _file_calls(p)
        if calls:
            found[rel] = calls
    assert not found, "file reads and writes outside the store:\n" + "\n".join(
        f"{k}: {v}" for k, v in found.items()
    )
