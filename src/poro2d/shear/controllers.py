"""The direct shear test's two controllers: the consolidation and the shear drive.

Both have the shape of the criterion's plate servo (:class:`poro2d.criterion.servo.PlateServo`):
a small object holding its settings, with one public method that drives a simulation.
The consolidation servoes the test's top plate through the criterion's own plate
controller (:class:`poro2d.criterion.lid.FlatPlate`); its stop rule is the shear test's
(equilibrium and the normal stress on target), not the criterion's force window.
"""

from __future__ import annotations

from dataclasses import dataclass

from poro2d.criterion.lid import FlatPlate
from poro2d.dem import Simulation
from poro2d.labtest.settle import ProgressFn, Settled, settle
from poro2d.shear.box import LOWER
from poro2d.shear.settings import ShearSettings


@dataclass(frozen=True)
class Settling(Settled):
    """How a consolidation ended (:class:`~poro2d.labtest.settle.Settled`: ``error`` the plate's
    |F / target - 1|), and the plate's height before it."""

    plate_height_before_m: float


@dataclass(frozen=True)
class Consolidation:
    """Servo the top plate to a normal force until the specimen is at equilibrium under it.

    Settled means the maximum unbalanced-force ratio below ``consolidation_ratio`` and the
    plate's force within ``stress_tolerance`` of the target, the servo on (``servo_gain``,
    ``servo_integral``, ``servo_max_speed``); at most ``consolidation_max_steps`` steps
    (:func:`poro2d.labtest.settle.settle`).
    """

    settings: ShearSettings
    progress: ProgressFn | None = None

    def settle(self, sim: Simulation, target: float) -> Settling:
        """Consolidate ``sim`` under ``target`` newtons on its top plate; the servo stays on after.

        The engine's clock starts again at 0.
        """
        s = self.settings
        plate = FlatPlate(sim)
        plate.servo(sim, target, s.servo_max_speed, s.servo_gain, s.servo_integral)
        y0 = plate.height(sim)
        end = settle(
            sim, lambda sm: abs(plate.force(sm) / target - 1.0), ratio_limit=s.consolidation_ratio,
            tolerance=s.stress_tolerance, max_steps=s.consolidation_max_steps, progress=self.progress,
        )  # fmt: skip
        return Settling(end.steps, end.ratio, end.error, end.reached, plate_height_before_m=y0)


@dataclass(frozen=True)
class ShearDrive:
    """The lower half of the split box (:data:`poro2d.shear.box.LOWER`) moving at ``velocity`` in +x."""

    velocity: float

    def start(self, sim: Simulation) -> None:
        """Set every wall of the lower half moving; the upper half and the plate's servo stay as they are."""
        for name in LOWER:
            sim.set_wall_velocity(name, (self.velocity, 0.0))


__all__ = ["Consolidation", "Settling", "ShearDrive"]
