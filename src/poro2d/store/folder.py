"""The store: the one place that reads and writes result files.

Protocols (the criterion, a shear test, a sweep's case, a calibration unit) compute typed
results; they never form a path. A protocol that keeps files, or resumes from them, is
handed a :class:`Store` and asks it by *name* for what it keeps: a JSON result, a table,
arrays, a saved simulation state, a checkpoint. ``store=None`` means nothing is kept.

A store is a folder and the rules every result file follows:

* every file is written atomically (:func:`poro2d.io_utils.atomic_path`): a killed run
  leaves no file that looks complete;
* JSON is strict (NaN written as ``null``), a typed result is written with its
  ``to_dict()`` and read back with ``from_dict()``;
* a stage's marker is written last (:class:`~poro2d.store.stage.ResumableStage`, reached
  through :meth:`Store.stage`), so a finished stage is one whose marker is there;
* what is read back is checked: a file that cannot be parsed is reported as missing
  (``None``), never half-used.

Sub-stores (:meth:`Store.child`) are the folders of the parts of a run (a trial, a test):
the names a protocol uses are relative, so a moved or copied folder resumes.

A run holds its folder through :meth:`Store.claim`, the one claim of an output folder: no
other run writes there meanwhile, and a folder of another kind of run is refused
(:mod:`poro2d.locks`).
"""

from __future__ import annotations

import csv
import functools
import inspect
import json
import os
import shutil
import zipfile
from collections.abc import Callable, Iterable, Iterator, Mapping
from contextlib import AbstractContextManager, contextmanager, nullcontext
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeVar

import numpy as np

from poro2d.dem import checkpoint, export
from poro2d.errors import InputError
from poro2d.io_utils import atomic_path, write_csv, write_json
from poro2d.locks import output_folder
from poro2d.store import digests
from poro2d.store.stage import Fingerprint, ResumableStage

if TYPE_CHECKING:
    import meshio
    import pandas as pd

    from poro2d.dem.simulation import Simulation

R = TypeVar("R")


def parquet_engine_available() -> bool:
    """True where pandas can write Parquet: pyarrow (the ``parquet`` extra) or fastparquet installed."""
    from importlib.util import find_spec

    return any(find_spec(engine) is not None for engine in ("pyarrow", "fastparquet"))


class Store:
    """Result files under one folder, named relative to it.

    ``parameter`` names the option the folder came from (``--out``), for refusals.
    """

    def __init__(self, root: str | os.PathLike, *, parameter: str = "--out") -> None:
        self._root = Path(root)
        self.parameter = parameter

    def __fspath__(self) -> str:
        return str(self._root)

    def __repr__(self) -> str:
        return f"Store({str(self._root)!r})"

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Store) and other.root == self._root

    def __hash__(self) -> int:
        return hash(self._root)

    @property
    def root(self) -> Path:
        """The folder (for messages, and for tools that write whole folders: figures, VTU)."""
        return self._root

    @contextmanager
    def claim(self, kind: str | None = None) -> Iterator[Store]:
        """Hold this store's folder for the block, as a ``kind`` run's (``"shear"``, ...).

        Refused, before any work, while another run writes the folder, or when it belongs to
        another kind of run (its marker, or its kind's own files); a rerun of the same kind
        goes on. A folder the block leaves empty is removed again (see
        :func:`poro2d.locks.output_folder`).
        """
        with output_folder(self.parameter, self._root, kind=kind):
            yield self

    def child(self, *parts: str) -> Store:
        """The store of a part of the run (``trials/02_n0.2300``), in a sub-folder."""
        return Store(self._root.joinpath(*parts), parameter=self.parameter)

    def path(self, name: str) -> Path:
        """Where ``name`` lives; its folder is made, so writers of other formats can use it."""
        p = self._root / name
        p.parent.mkdir(parents=True, exist_ok=True)
        return p

    def has(self, name: str) -> bool:
        """True when ``name`` is a file of this store."""
        return (self._root / name).is_file()

    def exists(self) -> bool:
        """True when the store's folder exists."""
        return self._root.is_dir()

    def names(self, pattern: str = "*") -> list[str]:
        """The store's entries matching ``pattern``, sorted (sub-stores included)."""
        if not self._root.is_dir():
            return []
        return sorted(p.name for p in self._root.glob(pattern) if p.name != digests.MANIFEST)

    # -- JSON and typed results -------------------------------------------------------

    def write_json(self, name: str, data: Mapping, *, config: bool = False) -> Path:
        """``data`` as strict JSON in ``name``, atomically (see :func:`poro2d.io_utils.write_json`)."""
        path = self._root / name
        write_json(path, data, config=config)
        return self._written(name)

    def read_json(self, name: str) -> Any:
        """The JSON in ``name``; None when it is missing, damaged or cannot be parsed."""
        return self._read(name, lambda path: json.loads(path.read_text()), (OSError, ValueError))

    def write_result(self, name: str, result: Any) -> Path:
        """A typed result's file (``result.to_dict()``), atomically."""
        return self.write_json(name, result.to_dict())

    def read_result(self, name: str, decode: Callable[[dict], R]) -> R | None:
        """``decode`` of the JSON object in ``name`` (a result class's ``from_dict``); None without one."""
        data = self.read_json(name)
        return decode(data) if isinstance(data, dict) else None

    # -- tables ---------------------------------------------------------------------------

    def write_csv(self, name: str, rows: Iterable[Mapping], header: list[str] | None = None) -> Path:
        """Rows of dicts as CSV, atomically (columns in first-seen order unless ``header``)."""
        write_csv(self._root / name, rows, header)
        return self._written(name)

    def read_rows(self, name: str) -> list[dict[str, str]] | None:
        """The rows of the CSV ``name`` as dicts of strings, as :meth:`write_csv` wrote them; None if missing.

        The text is left to the caller to convert: ``float()`` of it gives back the very
        numbers written (a table parser may round the last digit). A table changed since
        it was written reads as missing.
        """

        def rows(path: Path) -> list[dict[str, str]]:
            with open(path, newline="") as fh:
                return list(csv.DictReader(fh))

        return self._read(name, rows, (OSError, UnicodeDecodeError))

    def write_frame(self, name: str, frame: pd.DataFrame, **kw: Any) -> Path:
        """A pandas table as CSV, atomically (``kw`` go to ``DataFrame.to_csv``; no index by default)."""
        kw.setdefault("index", False)
        return self._write(name, lambda tmp: frame.to_csv(tmp, **kw))

    def read_frame(self, name: str, **kw: Any) -> pd.DataFrame:
        """The CSV ``name`` as a pandas table (``kw`` go to ``pandas.read_csv``)."""
        import pandas as pd

        self.check_intact(name)
        return pd.read_csv(self._root / name, **kw)

    def write_parquet(self, name: str, frame: pd.DataFrame) -> Path | None:
        """A pandas table as Parquet (no index), atomically: typed columns for the next reader.

        None, and nothing written, where pandas has no Parquet engine (pyarrow comes with the
        ``parquet`` extra, about 170 MB); a file of that name from an earlier run is removed
        rather than left behind, out of date.
        """
        if not parquet_engine_available():
            self.remove(name)
            return None
        path = self._root / name
        with atomic_path(path) as tmp:
            frame.to_parquet(tmp, index=False)
        return path

    def write_text(self, name: str, text: str) -> Path:
        """A text file (a report, a script), atomically."""
        return self._write(name, lambda tmp: tmp.write_text(text))

    def read_text(self, name: str) -> str | None:
        """The text in ``name``; None when it is missing, damaged or unreadable."""
        return self._read(name, Path.read_text, (OSError, UnicodeDecodeError))

    # -- arrays and simulation states -------------------------------------------------

    def write_arrays(self, name: str, **arrays: Any) -> Path:
        """Named arrays in one ``.npz``, atomically."""
        return self._write(name, lambda tmp: np.savez(tmp, **arrays), suffix=".npz")

    def read_arrays(self, name: str) -> dict[str, np.ndarray] | None:
        """The arrays of ``name`` by name (all read now, so the file is closed); None if missing or broken."""

        def arrays(path: Path) -> dict[str, np.ndarray]:
            with np.load(path, allow_pickle=False) as z:
                return {k: z[k] for k in z.files}

        return self._read(name, arrays, (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile))

    def write_mesh(self, name: str, mesh: meshio.Mesh) -> Path:
        """A mesh as the VTU file ``name`` for ParaView, atomically (:func:`poro2d.dem.export.write_mesh`)."""
        export.write_mesh(mesh, self._root / name)
        return self._written(name)

    def save_state(self, name: str, sim: Simulation, extra: dict | None = None) -> Path:
        """A simulation's whole state (:func:`poro2d.dem.checkpoint.save`)."""
        checkpoint.save(sim, self._root / name, extra=extra)
        return self._written(name)

    def load_state(self, name: str, threads: int | None = None) -> Simulation:
        """A saved state as a simulation (:func:`poro2d.dem.checkpoint.load`; a damaged file is refused)."""
        self.check_intact(name)
        return checkpoint.load(self._root / name, threads=threads)

    def read_state(self, name: str) -> tuple[dict, dict[str, np.ndarray]]:
        """(metadata, arrays) of a saved state, read once in full (:func:`poro2d.dem.checkpoint.read`).

        For a state that starts several runs: build each with
        :func:`poro2d.dem.checkpoint.from_content` instead of reading the file again.
        """
        self.check_intact(name)
        return checkpoint.read(self._root / name)

    def state_meta(self, name: str) -> dict:
        """The metadata of a saved state as its JSON holds it (:func:`poro2d.dem.checkpoint.read_meta`)."""
        self.check_intact(name)
        return checkpoint.read_meta(self._root / name)

    def copy(self, name: str, to: str | Store, as_name: str | None = None) -> Path:
        """Copy ``name`` atomically to ``to``: a name here, or a store (as ``as_name``, default the same)."""
        dest_store, dest = (to, as_name or name) if isinstance(to, Store) else (self, to)
        target = dest_store.root / dest
        with atomic_path(target) as tmp:
            shutil.copyfile(self._root / name, tmp)
        digests.record(target.parent, target.name)
        return target

    def remove(self, name: str) -> None:
        """Remove the file ``name`` if it is there."""
        try:
            (self._root / name).unlink()
        except FileNotFoundError:
            return
        digests.forget(self._root, name)

    # -- integrity ------------------------------------------------------------------------

    def _write(self, name: str, write: Callable[[Path], Any], suffix: str | None = None) -> Path:
        """``write(tmp)`` made ``name`` atomically, its digest noted in the manifest."""
        with atomic_path(self._root / name, suffix=suffix) as tmp:
            write(tmp)
        return self._written(name)

    def _read(self, name: str, read: Callable[[Path], R], errors: tuple[type[Exception], ...]) -> R | None:
        """``read`` of the file ``name``; None when it differs from what was written, or ``read`` raises
        one of ``errors`` (missing, unreadable, not of its format)."""
        if not self.intact(name):
            return None
        try:
            return read(self._root / name)
        except errors:
            return None

    def _written(self, name: str) -> Path:
        digests.record(self._root, name)
        return self._root / name

    def intact(self, name: str) -> bool:
        """False when ``name`` differs from what this store wrote (edited, truncated, replaced)."""
        return digests.intact(self._root, name)

    def check_intact(self, name: str) -> None:
        """Refuse, on one line naming it, a file that differs from what this store wrote."""
        if not self.intact(name):
            what = "changed since it was written" if self.has(name) else "missing since it was written"
            raise InputError(
                str(self._root / name), what, "the file as poro2d wrote it",
                "delete it (or its folder) to have it computed again",
            )  # fmt: skip

    # -- stages ---------------------------------------------------------------------------

    def stage(self, fingerprint: Fingerprint, **kw: Any) -> ResumableStage:
        """The resumable stages of this store bound to ``fingerprint`` (``kw``: see ResumableStage)."""
        kw.setdefault("parameter", self.parameter)
        return ResumableStage(self._root, fingerprint, **kw)

    def checkpoints(self, name: str = "checkpoint.npz") -> Checkpoints:
        """A checkpoint reporter for a long run kept in ``name`` (see :class:`Checkpoints`)."""
        return Checkpoints(self, name)


class Checkpoints:
    """Saves a long run's state at its Python events and gives it back on a rerun.

    A protocol that runs long (a shear test's drive) takes one of these instead of a
    folder: :meth:`resume` returns the saved state and its metadata (None on a first run),
    :meth:`save` keeps the state now, :meth:`clear` drops it once the stage's result is
    written.
    """

    def __init__(self, store: Store, name: str) -> None:
        self.store = store
        self.name = name

    def resume(self, threads: int | None = None) -> tuple[Simulation, dict] | None:
        """The saved state and the ``extra`` it was saved with; None when there is none.

        A checkpoint that differs from what was saved, or cannot be read (truncated where no
        manifest tells), is dropped: the stage starts again.
        """
        if not self.store.has(self.name):
            return None
        try:
            extra = self.store.state_meta(self.name).get("extra", {})
            return self.store.load_state(self.name, threads=threads), extra
        except InputError:
            self.store.remove(self.name)
            return None

    def save(self, sim: Simulation, extra: dict | None = None) -> None:
        """Keep ``sim``'s state now (atomically), with ``extra`` (where the protocol was)."""
        self.store.save_state(self.name, sim, extra=extra)

    def clear(self) -> None:
        """Drop the checkpoint (the stage it served is finished)."""
        self.store.remove(self.name)


def claimed(store: Store | None, kind: str | None = None) -> AbstractContextManager[Store | None]:
    """``store.claim(kind)``; for None (a run that keeps nothing) nothing is held."""
    return nullcontext() if store is None else store.claim(kind)


def claims(kind: str, argument: str = "store"):
    """Decorator: the call holds its ``argument`` claimed as ``kind``'s (:meth:`Store.claim`) throughout.

    ``argument`` is a store, None (nothing held), or a command's folder (a path, named ``--out``).
    """

    def decorate(func):
        signature = inspect.signature(func)

        @functools.wraps(func)
        def run(*args, **kwargs):
            bound = signature.bind(*args, **kwargs)
            bound.apply_defaults()
            target = bound.arguments[argument]
            store = target if target is None or isinstance(target, Store) else Store(target)
            with claimed(store, kind):
                return func(*args, **kwargs)

        return run

    return decorate


def walk(store: Store, pattern: str) -> Iterator[Store]:
    """The sub-stores of ``store`` whose folder names match ``pattern``, sorted."""
    for name in store.names(pattern):
        if (store.root / name).is_dir():
            yield store.child(name)


__all__ = ["Checkpoints", "Store", "claimed", "claims", "walk"]
