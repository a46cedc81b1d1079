"""The 2D DEM engine: disks, wall segments, the linear contact law, compiled steps."""

from poro2d.dem import checkpoint
from poro2d.dem.model import ContactModel
from poro2d.dem.reporters import Every, Reporter
from poro2d.dem.simulation import RunResult, Simulation, SimulationError
from poro2d.dem.state import Particles, Walls

__all__ = [
    "checkpoint", "ContactModel", "Every", "Particles", "Reporter", "RunResult", "Simulation",
    "SimulationError", "Walls",
]  # fmt: skip
