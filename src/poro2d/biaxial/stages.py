"""The biaxial test's two stages: consolidation to sigma_3 and shearing at constant sigma_3.

Both drive the engine in blocks of steps (:meth:`poro2d.dem.Simulation.run`); between the
blocks, in Python, their reporters (:mod:`poro2d.labtest.reporters`) only renew the walls'
targets (a stress times the current contact length) and read a row.
"""

from __future__ import annotations

import math
import sys
import time
from dataclasses import dataclass, field

import numpy as np

from poro2d.biaxial.box import BiaxialBox, BoxSize
from poro2d.biaxial.curve import BiaxialRow, curve_row
from poro2d.biaxial.settings import BiaxialSettings
from poro2d.biaxial.stiffness import contact_kn, overlap_ratio, stiffness_number
from poro2d.dem import Simulation
from poro2d.dem.export import frame_of
from poro2d.labtest.records import BoxRecord, ConsolidationRecord
from poro2d.labtest.reporters import CurveRecorder, ProgressReporter, StopTest, series_reporters
from poro2d.labtest.settle import ProgressFn, Settled
from poro2d.labtest.settle import settle as settle_servoed
from poro2d.measure.coordination import coordination_number
from poro2d.measure.fabric import rose
from poro2d.store import Store

#: the first part of the axial strain, where the side walls only start to follow, left out of
#: the sigma_3 check
SIDE_START_STRAIN = 0.01


def servo_targets(
    sim: Simulation, sigma_pa: float, settings: BiaxialSettings, *, top: bool, top_pa: float | None = None
) -> None:
    """Servo the side walls to ``sigma_pa`` over their current contact length, and the plate when
    ``top`` (to ``top_pa``, by default ``sigma_pa``)."""
    s = BiaxialBox.size(sim)
    side = sigma_pa * s.height * s.thickness
    BiaxialBox.servo(sim, "left", side, settings)
    BiaxialBox.servo(sim, "right", side, settings)
    if top:
        plate = sigma_pa if top_pa is None else top_pa
        BiaxialBox.servo(sim, "top", plate * s.width * s.thickness, settings)


def stress_errors(sim: Simulation, sigma_pa: float, top_pa: float | None = None) -> list[float]:
    """|stress / target - 1| of the plate (target ``top_pa``, by default ``sigma_pa``), the left and
    the right wall (target ``sigma_pa``)."""
    s1, _, left, right = BiaxialBox.stresses(sim)
    plate = sigma_pa if top_pa is None else top_pa
    return [abs(s1 / plate - 1.0), abs(left / sigma_pa - 1.0), abs(right / sigma_pa - 1.0)]


def settle(
    sim: Simulation, sigma_pa: float, settings: BiaxialSettings, *, top_pa: float | None,
    phase: str, progress: ProgressFn | None = None, fixed_plate: bool = False,
) -> Settled:  # fmt: skip
    """Run until equilibrium (:func:`poro2d.labtest.settle.settle`): the side walls servoed to
    ``sigma_pa`` and the plate to ``top_pa`` (or held where it is, ``fixed_plate``), their targets
    renewed at every check as the box changes. Reached: the maximum unbalanced-force ratio below
    ``consolidation_ratio`` and each servoed wall's stress within ``stress_tolerance`` of its
    target, within ``consolidation_max_steps`` steps."""
    top = not fixed_plate

    def error(sm: Simulation) -> float:
        err = stress_errors(sm, sigma_pa, top_pa)
        return max(err if top else err[1:])

    def renew(sm: Simulation) -> None:
        servo_targets(sm, sigma_pa, settings, top=top, top_pa=top_pa)

    if fixed_plate:
        sim.set_wall_velocity("top", (0.0, 0.0))
    renew(sim)
    return settle_servoed(
        sim, error, ratio_limit=settings.consolidation_ratio, tolerance=settings.stress_tolerance,
        max_steps=settings.consolidation_max_steps, renew=renew, progress=progress, phase=phase,
    )  # fmt: skip


def porosity(sim: Simulation) -> float:
    """The box's porosity: 1 - disk area / box area."""
    s = BiaxialBox.size(sim)
    return 1.0 - float(np.sum(np.pi * sim.particles.radius**2)) / (s.width * s.height)


def consolidate(
    sim: Simulation, box: BiaxialBox, confining_kpa: float, settings: BiaxialSettings,
    progress: ProgressFn | None = None,
) -> ConsolidationRecord:  # fmt: skip
    """Servo the plate and the side walls to sigma_3 until equilibrium; refuse loudly if not reached.

    Reached: the maximum unbalanced-force ratio below ``consolidation_ratio`` and every wall's
    stress within ``stress_tolerance`` of sigma_3, within ``consolidation_max_steps`` steps.
    """
    t0 = time.perf_counter()
    sigma = confining_kpa * 1e3
    end = settle(sim, sigma, settings, top_pa=None, phase="consolidating", progress=progress)
    if not end.reached:
        raise RuntimeError(
            f"consolidation to sigma_3 = {confining_kpa:g} kPa did not reach equilibrium within "
            f"{settings.consolidation_max_steps} steps (unbalanced ratio {end.ratio:.2e}, limit "
            f"{settings.consolidation_ratio:g}; stress error {end.error:.2%}, "
            f"limit {settings.stress_tolerance:.0%})"
        )
    s1, _, left, right = BiaxialBox.stresses(sim)
    size = BiaxialBox.size(sim)
    kn = contact_kn(sim)
    return ConsolidationRecord(
        confining_stress_kpa=confining_kpa, steps=end.steps, max_unbalanced_ratio=end.ratio,
        sigma_1_kpa=s1 / 1e3, sigma_3_left_kpa=left / 1e3, sigma_3_right_kpa=right / 1e3,
        max_stress_error=end.error, width_m=size.width, height_m=size.height, porosity=porosity(sim),
        coordination_number=coordination_number(sim), wall_time_s=time.perf_counter() - t0,
        box=BoxRecord(width=box.width, height=box.height, thickness=box.thickness), contact_kn=kn,
        stiffness_number=stiffness_number(kn, sigma, size.thickness), mean_overlap_ratio=overlap_ratio(sim),
    )  # fmt: skip


@dataclass
class Shearing:
    """The plate moves down at ``strain_rate * H0``; the side walls stay servoed at sigma_3.

    ``strain_rate``: the test's (:func:`poro2d.biaxial.settings.auto_strain_rate`).

    One row per ``record_strain`` of axial strain (:func:`poro2d.biaxial.curve.curve_row`)
    until the axial strain reaches ``max_strain``; the side walls' targets are renewed at
    every row (sigma_3 over the current height). With ``settings.vtk_every`` and a ``store``, a
    step of the ParaView series every ``vtk_every`` steps (in ``vtk/``, at the axial strain).
    """

    sim: Simulation
    confining_kpa: float
    settings: BiaxialSettings
    strain_rate: float
    d50: float
    rho: float
    progress: ProgressFn | None = None
    store: Store | None = None
    roses: list[np.ndarray] = field(default_factory=list, init=False, repr=False)

    def run(self) -> tuple[list[BiaxialRow], float]:
        """The curve's rows and the plate's velocity (m/s); the contact orientations of every row
        are kept in ``roses``."""
        sim, s = self.sim, self.settings
        sigma = self.confining_kpa * 1e3
        start: BoxSize = BiaxialBox.size(sim)
        velocity = self.strain_rate * start.height
        sim.set_wall_velocity("top", (0.0, -velocity))
        servo_targets(sim, sigma, s, top=False)
        steps_per_row = max(1, round(s.record_strain * start.height / (velocity * sim.dt)))
        sim.reset_clock()

        def row(sm: Simulation, step: int | None = None) -> BiaxialRow:  # the side walls' targets first
            if step is None:
                servo_targets(sm, sigma, s, top=False)
            contacts = sm.contacts()
            self.roses.append(rose(contacts))
            at = sm.step_count if step is None else step
            return curve_row(sm, start, at, self.d50, self.rho, self.strain_rate, contacts)

        self.roses = []
        rows = [row(sim, 0)]

        def strained(_sim: Simulation | None = None) -> bool:
            return rows[-1].axial_strain >= s.max_strain

        share = ProgressReporter(
            steps_per_row,
            self.progress,
            "shearing",
            lambda *_: min(rows[-1].axial_strain / s.max_strain, 1.0),
        )
        if not strained():  # then as many rows as reaching max_strain takes
            recorder = CurveRecorder(steps_per_row, row, rows)
            series = series_reporters(
                s.vtk_every, self.store, "axial_strain", sim, frame_of,
                lambda sm: (sm.step_count, sm.time, math.log(start.height / BiaxialBox.size(sm).height)),
            )  # fmt: skip
            sim.run(sys.maxsize, reporters=[recorder, share, *series, StopTest(steps_per_row, strained)])
        return rows, velocity


__all__ = [
    "Shearing", "consolidate", "porosity", "servo_targets",
    "settle",
]  # fmt: skip
