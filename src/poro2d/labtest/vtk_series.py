"""A run's ParaView time series: one VTU file per step and the ``.pvd`` collections that list them.

A test asked for a series (its ``vtk_every``) keeps it in the ``vtk/`` folder of its store:
``step_<step>.vtu`` (:func:`poro2d.dem.export.step_mesh`: disks, walls, contact network),
``series.pvd`` (each step at the engine's time, in s) and ``series_<measure>.pvd`` (each step at
the test's own measure: the shear displacement, the axial strain, the shear strain, the plate's
height), both read by ParaView as one time series. A run resumed from a checkpoint reads the
steps back from ``series.pvd``, drops those after its checkpoint and writes them again, so the
series reads as one run's. The files go through the store (atomic, in its manifest), the
collections after the step's file.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from xml.sax.saxutils import quoteattr

from poro2d.dem.export import Frame, step_mesh
from poro2d.store import Store

#: the folder of a run's store that holds its series, and the files that list its steps
FOLDER = "vtk"
SERIES = "series.pvd"


def collection(entries: list[dict], key: str) -> str:
    """The ``.pvd`` XML listing ``entries`` (each with ``file`` and ``key``) at timestep ``key``.

    Each data set also names its ``step`` and every number of its entry as attributes, which
    ParaView reads past.
    """
    lines = ['<?xml version="1.0"?>', '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">']
    lines.append("  <Collection>")
    for e in entries:
        extra = " ".join(f"{k}={quoteattr(repr(v))}" for k, v in e.items() if k not in ("file", key))
        lines.append(f'    <DataSet timestep="{e[key]!r}" part="0" file={quoteattr(e["file"])} {extra}/>')
    lines += ["  </Collection>", "</VTKFile>", ""]
    return "\n".join(lines)


def read_entries(text: str | None, measure: str) -> list[dict]:
    """The steps a ``series.pvd`` written by :func:`collection` lists (none when it is missing,
    damaged or of another measure)."""
    try:
        sets = ET.fromstring(text).findall("./Collection/DataSet") if text else []
        return [
            {"step": int(d.get("step")), "time": float(d.get("timestep")), measure: float(d.get(measure)),
             "file": d.get("file")}
            for d in sets
        ]  # fmt: skip
    except (ET.ParseError, TypeError, ValueError):
        return []


@dataclass
class VtkSeries:
    """The series in ``store`` (a run's ``vtk/`` folder), its steps at the test's ``measure``.

    ``entries``: the steps written, in order (``step``, ``time``, the measure, ``file``).
    """

    store: Store
    measure: str
    entries: list[dict] = field(default_factory=list)

    @classmethod
    def open(cls, store: Store | None, measure: str, start: int) -> VtkSeries | None:
        """The series of the run kept in ``store`` (None: none), continuing after stage step ``start``.

        A fresh stage (``start`` 0) starts a new series; a resumed one keeps the steps up to its
        checkpoint's, as the run that wrote them had them.
        """
        if store is None:
            return None
        series_store = store.child(FOLDER)
        kept = read_entries(series_store.read_text(SERIES), measure) if start > 0 else []
        return cls(series_store, measure, [e for e in kept if e["step"] <= start])

    def write(self, frame: Frame, step: int, time: float, value: float) -> None:
        """Keep ``frame`` as stage step ``step`` at engine time ``time`` (s) and measure ``value``."""
        name = f"step_{step:010d}.vtu"
        numbers = {"step": int(step), "time": float(time), self.measure: float(value)}
        self.store.write_mesh(name, step_mesh(frame))
        self.entries = [e for e in self.entries if e["step"] < step] + [{**numbers, "file": name}]
        self.store.write_text(f"series_{self.measure}.pvd", collection(self.entries, self.measure))
        self.store.write_text(SERIES, collection(self.entries, "time"))


__all__ = ["FOLDER", "SERIES", "VtkSeries", "collection", "read_entries"]
