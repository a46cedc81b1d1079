"""A run's ParaView time series: one VTU file per step and the ``.pvd`` collections that list them.

A test asked for a series (its ``vtk_every``) keeps it in the ``vtk/`` folder of its store:
``step_<step>.vtu`` (:func:`poro2d.dem.export.step_mesh`: disks, walls, contact network),
``series.pvd`` (each step at the engine's time, in s) and ``series_<measure>.pvd`` (each step at
the test's own measure: the shear displacement, the axial strain, the shear strain), both read by
ParaView as one time series. ``series.json`` lists the steps written; a run resumed from a
checkpoint drops the steps after it and writes them again, so the series reads as one run's.
The files go through the store (atomic, in its manifest), the collections last.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from xml.sax.saxutils import quoteattr

from poro2d.dem.export import Frame, step_mesh
from poro2d.store import Store

#: the folder of a run's store that holds its series, and the files that list its steps
FOLDER = "vtk"
SERIES = "series.pvd"
STEPS = "series.json"


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
        folder = store.child(FOLDER)
        kept = folder.read_json(STEPS) if start > 0 else None
        steps = kept.get("steps", []) if isinstance(kept, dict) and kept.get("measure") == measure else []
        return cls(folder, measure, [e for e in steps if isinstance(e, dict) and e.get("step", -1) <= start])

    def write(self, frame: Frame, step: int, time: float, value: float) -> None:
        """Keep ``frame`` as stage step ``step`` at engine time ``time`` (s) and measure ``value``."""
        name = f"step_{step:010d}.vtu"
        numbers = {"step": int(step), "time": float(time), self.measure: float(value)}
        self.store.write_mesh(name, step_mesh(frame))
        self.entries = [e for e in self.entries if e["step"] < step] + [{**numbers, "file": name}]
        self.store.write_json(STEPS, {"measure": self.measure, "steps": self.entries})
        self.store.write_text(f"series_{self.measure}.pvd", collection(self.entries, self.measure))
        self.store.write_text(SERIES, collection(self.entries, "time"))


__all__ = ["FOLDER", "SERIES", "STEPS", "VtkSeries", "collection"]
