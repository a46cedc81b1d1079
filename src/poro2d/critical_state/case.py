"""A critical-state case: everything one periodic shear run depends on, as one frozen value.

The grading and the number of disks make the packing (radii drawn by
:func:`poro2d.grading.draw_disks` from the seed); the micro-parameters are the particle
friction ``f_p`` and the rolling friction ``mu_r`` (against R = r_i r_j / (r_i + r_j), as the
engine writes it); the loading is the normal pressure ``P`` held by the barostat and the
inertial number ``I = gamma_dot d_mean sqrt(rho / P)`` that sets the shear rate. Contact
stiffnesses and density are Table 1's, as the direct shear test uses them (per body, combined
in series: 2e5 N/m per contact), unless ``stiffness_number`` asks for the rigid-grain limit:
then the contact stiffness is scaled with the pressure, kn = kappa P t, so that every pressure
sees the same kappa = kn / (P t) (the inverse of the typical contact strain). Cases for several
seeds come from one with :meth:`with_seed`, for several pressures with :meth:`at_pressure`.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any, ClassVar, Self

from poro2d.dem.contact_law import MAX_ROLLING_FRICTION, series
from poro2d.errors import InputError, Integer, Real, check_fields
from poro2d.grading import GradingCurve, paper_grading
from poro2d.identity import outside_identity
from poro2d.labtest.settings import TestSettings, lab_ranges
from poro2d.paper_data import TABLE_1

#: disks of the cell: below about 200 the stress ratio's fluctuations swamp its mean; above
#: 20000 one run takes hours on one thread
DISKS_RANGE = (200, 20_000)
#: the inertial numbers a case may ask for: quasi-static below 1e-3, dense flow up to 0.1
INERTIAL_RANGE = (1e-5, 0.1)
#: kappa = kn / (P t) a case may ask for: below 10 contacts overlap by a tenth of a diameter;
#: 1e4 is the stiff end of the rigid-grain limit (1e3-1e4, Roux & Combe), and the time step
#: shrinks as 1 / sqrt(kappa): at 1e4 and 100 kPa it is a sixth of Table 1's
STIFFNESS_NUMBER_RANGE = (10.0, 1e4)
#: disk thickness (m), that of the specimens (SpecimenSpec): masses and stresses per volume
THICKNESS = 0.008

CASE_RANGES = {
    "disks": Integer(*DISKS_RANGE),
    "particle_friction": Real(0.0, 10.0),
    "rolling_friction": Real(0.0, MAX_ROLLING_FRICTION),
    "pressure_kpa": Real(1.0, 10_000.0),
    "inertial_number": Real(*INERTIAL_RANGE),
    "strain": Real(0.5, 100.0),
    "window_start": Real(0.0, 99.0),
    "seed": Integer(0, 2**31 - 1),
    "kn_particle": Real(0.0, None, lo_open=True),
    "ks_particle": Real(0.0, None, lo_open=True),
    "solid_density": Real(0.0, None, lo_open=True),
    "restitution": Real(0.1, 1.0),
    "dt_safety": Real(0.0, 1.0, lo_open=True),
    "barostat_time": Real(1.0, 1000.0),
    "record_strain": Real(1e-4, 0.1),
    "blocks": Integer(3, 100),
    "mu_drift_limit": Real(0.0, 1.0, lo_open=True),
    "stiffness_number": Real(*STIFFNESS_NUMBER_RANGE, or_none=True),
    "solid_drift_limit": Real(0.0, 0.1, lo_open=True),
    **lab_ranges("vtk_every"),
}


@dataclass(frozen=True)
class CriticalStateCase(TestSettings):
    """One periodic shear run (SI but the pressure in kPa; strains are shear strains gamma), also
    the ``case`` its result files keep (:class:`~poro2d.labtest.settings.TestSettings`).

    disks: about how many disks (the drawn total area is ``disks`` mean disk areas); strain:
    gamma at which the run ends; window_start: gamma where the steady-state window begins
    (it ends at ``strain``); restitution: of the contact dashpot (no local damping, which
    would drag the flow); barostat_time: the barostat's relaxation time in sound-crossing times
    of the cell (slow enough not to ring); record_strain: gamma between two rows of the
    series; blocks: the window is cut into this many blocks for the standard error;
    mu_drift_limit and solid_drift_limit: the largest change over the window (a least-squares
    slope times its width) of the stress ratio and the solid fraction for a steady state;
    vtk_every (steps; 0: none): the shear's ParaView series (:mod:`poro2d.labtest.vtk_series`), an
    output outside the run's identity, kept in the files only when asked for.
    """

    grading: GradingCurve = field(default_factory=paper_grading)
    disks: int = 1500
    particle_friction: float = 0.5
    rolling_friction: float = 0.0
    pressure_kpa: float = 100.0
    inertial_number: float = 1e-3
    strain: float = 3.0
    window_start: float = 1.0
    seed: int = 0
    kn_particle: float = TABLE_1.kn_particle
    ks_particle: float = TABLE_1.ks_particle
    solid_density: float = TABLE_1.solid_density
    restitution: float = 0.5
    dt_safety: float = 0.8
    barostat_time: float = 4.0
    record_strain: float = 0.01
    blocks: int = 5
    mu_drift_limit: float = 0.03
    solid_drift_limit: float = 0.005
    stiffness_number: float | None = None
    vtk_every: int = outside_identity(0)

    OMITTED: ClassVar[dict] = {"stiffness_number": None, "vtk_every": 0}

    def __post_init__(self) -> None:
        if not isinstance(self.grading, GradingCurve):
            raise InputError("grading", type(self.grading).__name__, "a GradingCurve")
        check_fields(self, CASE_RANGES)
        width = self.strain - self.window_start
        if width < self.blocks * self.record_strain * 3:
            least = self.window_start + self.blocks * self.record_strain * 3
            raise InputError("strain", self.strain, f">= {least:g} (3 rows a block after window_start)")

    def with_seed(self, seed: int) -> CriticalStateCase:
        return replace(self, seed=seed)

    def at_pressure(self, pressure_kpa: float) -> CriticalStateCase:
        return replace(self, pressure_kpa=pressure_kpa)

    def contact_stiffness(self) -> tuple[float, float]:
        """(kn, ks) of a contact (N/m): Table 1's per-body values in series, or, with
        ``stiffness_number``, kn = kappa P t and ks in Table 1's ratio ks / kn."""
        kn = float(series(self.kn_particle, self.kn_particle))
        ks = float(series(self.ks_particle, self.ks_particle))
        if self.stiffness_number is None:
            return kn, ks
        scaled = self.stiffness_number * self.pressure_kpa * 1e3 * THICKNESS
        return scaled, scaled * ks / kn

    def kappa(self) -> float:
        """The stiffness number kn / (P t) of the case's contacts at its pressure."""
        return self.contact_stiffness()[0] / (self.pressure_kpa * 1e3 * THICKNESS)

    def to_dict(self) -> dict[str, Any]:
        """The case as its result files keep it: every field in order, the grading as its model
        sizes, percent passing and source, ``stiffness_number`` only when set."""
        row = super().to_dict()
        g = self.grading
        row["grading"] = {
            "sizes_m": list(g.sizes_m), "percent_passing": list(g.percent_passing), "source": g.source,
        }  # fmt: skip
        return row

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> Self:
        """The case a result file keeps, as kept (:meth:`TestSettings.from_dict`), its grading a curve."""
        case = super().from_dict(data)
        g = case.grading
        curve = GradingCurve(g["sizes_m"], g["percent_passing"], source=g["source"])
        object.__setattr__(case, "grading", curve)  # frozen, and read unchecked as the kit reads a file
        return case


__all__ = [
    "CASE_RANGES",
    "CriticalStateCase",
    "DISKS_RANGE",
    "INERTIAL_RANGE",
    "STIFFNESS_NUMBER_RANGE",
    "THICKNESS",
]
