"""Carry a specimen into other DEM codes and back: LAMMPS, YADE, PFC2D and a CSV table.

``specimen_data`` holds a specimen as plain numbers (:class:`SpecimenData`), read from a
poro2d checkpoint; one module per target writes it (``lammps``, ``yade``, ``pfc``,
``csv_table``); ``check`` runs the criterion's check on an imported specimen and
``agreement`` runs the same specimen in LAMMPS and in poro2d and compares them.
"""

from poro2d.interop.specimen_data import SpecimenData, WallData, from_checkpoint, from_simulation

__all__ = ["SpecimenData", "WallData", "from_checkpoint", "from_simulation"]
