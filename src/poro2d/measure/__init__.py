"""Measurements of a packing: porosities, stress, coordination, energy, one record per quantity.

Every measurement reads a simulation's public stores (through
:meth:`poro2d.dem.simulation.Simulation.contacts`) or plain arrays of disk centres and
radii; none writes a file. One module per quantity:

- ``porosity``: a region's porosity with disks clipped exactly (rectangle, circle) and the
  paper's box porosity n' (:func:`box_porosity`);
- ``disks``: the checks every porosity measure makes of its disks and box, the median
  diameter by area (:func:`mass_d50`);
- ``surface``: the free surface and the gap under the top plate or a segmented lid;
- ``interior``: measurement circles in the interior, clear of walls and free surface;
- ``laguerre``: the Laguerre cells, a local porosity per disk;
- ``specimen_porosity``: all of these for a specimen in one record,
  :class:`SpecimenPorosity` (:func:`measure_specimen`; ``specimen_porosity.json``);
- ``specimen_state``: porosity and stress in horizontal bands (:func:`specimen_state`);
- ``stress``: the Love-Weber average stress of the disks in a rectangle;
- ``coordination``: contacts per disk, with or without rattlers;
- ``fabric``: contact-orientation and force anisotropies, mechanical coordination (:class:`Fabric`);
- ``energy``: the kinetic energy of the disks.
"""

from poro2d.measure.coordination import coordination_number
from poro2d.measure.disks import mass_d50
from poro2d.measure.energy import kinetic_energy
from poro2d.measure.fabric import Fabric, cell_fabric, measure_fabric
from poro2d.measure.porosity import box_porosity, disk_area, porosity_circle, porosity_rect
from poro2d.measure.specimen_porosity import SpecimenPorosity, measure_specimen
from poro2d.measure.specimen_state import specimen_state
from poro2d.measure.stress import average_stress

__all__ = [
    "Fabric",
    "SpecimenPorosity",
    "average_stress",
    "box_porosity",
    "cell_fabric",
    "coordination_number",
    "disk_area",
    "kinetic_energy",
    "mass_d50",
    "measure_fabric",
    "measure_specimen",
    "porosity_circle",
    "porosity_rect",
    "specimen_state",
]
