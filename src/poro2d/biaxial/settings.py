"""Settings of a biaxial test, and the inertial number that says whether it is quasi-static."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

from poro2d.errors import InputError, Ranges, Real, check_fields
from poro2d.identity import outside_identity
from poro2d.labtest.settings import (
    NORMAL_STRESS_RANGE_KPA,
    SERVO_AND_WALLS,
    DisksAndEngine,
    TestSettings,
    lab_ranges,
)
from poro2d.paper_data import TABLE_1
from poro2d.typed_result import with_fields

#: the confining stresses (kPa) a test may be run at: the direct shear test's normal stresses,
#: for the same reasons (a soft contact's overlap above, the specimen's weight below)
CONFINING_RANGE_KPA = NORMAL_STRESS_RANGE_KPA
#: the largest axial strain a test may reach: past a half the specimen is a flat layer
MAX_AXIAL_STRAIN = 0.5
#: most rows a curve may hold
MAX_RECORDS = 100_000
#: the slowest strain rate a test may be run at (1/s): at the quick specimen's time step (about
#: 5e-6 s with Table 1's stiffness) the default 0.2 of axial strain takes 0.2 / (1e-3 x 5e-6) = 4e7
#: steps, four times the consolidation's largest budget (MAX_CONSOLIDATION_STEPS): days of one core.
#: A slower test would not end in any run's time, and is refused before any work
MIN_STRAIN_RATE = 1e-3

#: the share of the end deviator the unloading probe takes off (:mod:`poro2d.biaxial.elastic`): enough
#: to read a slope above the equilibrium's noise (0.05-0.1 was not on the quick specimen at 50 kPa),
#: little enough that fewer contacts slide back
PROBE_UNLOAD_RANGE = (0.05, 0.9)
#: the stiffness numbers a test may be run at (:mod:`poro2d.biaxial.stiffness`): below 10 the
#: overlaps pass a tenth of a diameter, above 1e5 the time step makes a test last hours
STIFFNESS_NUMBER_RANGE = (10.0, 1e5)

#: what each setting of :class:`BiaxialSettings` may be (checked in this order)
BIAXIAL_RANGES: Ranges = {
    "strain_rate": Real(MIN_STRAIN_RATE, 100.0, or_none=True),
    "max_strain": Real(0.0, MAX_AXIAL_STRAIN, lo_open=True),
    "record_strain": Real(0.0, 0.05, lo_open=True),
    **lab_ranges("consolidation_ratio", "consolidation_max_steps", "stress_tolerance", *SERVO_AND_WALLS),
    **lab_ranges("particle_friction", "rolling_friction", "local_damping", "density_scale", "dt_safety"),
    "inertial_limit": Real(0.0, 0.1, lo_open=True),
    "smoothing_strain": Real(0.0, 0.1),
    "critical_window": Real(0.0, 0.5, lo_open=True),
    "critical_rate_limit": Real(0.0, 1.0, lo_open=True),
    "probe_unload": Real(*PROBE_UNLOAD_RANGE, or_none=True),
    "stiffness_number": Real(*STIFFNESS_NUMBER_RANGE, or_none=True),
    **lab_ranges("vtk_every"),
}


@dataclass
@with_fields(DisksAndEngine, after="friction_wall")
class BiaxialSettings(TestSettings):
    """Settings of a biaxial test (SI units; strains are fractions, compression positive), also
    the ``settings`` its files keep (:class:`~poro2d.labtest.settings.TestSettings`; ``probe_unload``
    and ``stiffness_number`` only when given, as before they existed).

    strain_rate (1/s): the top plate moves down at ``strain_rate * H0`` (H0 the specimen's
    height after consolidation); None (the default): :func:`auto_strain_rate`, 0.2 /s or slower
    in a box so wide that its side walls could not follow; max_strain: the axial strain where the test ends;
    record_strain: axial strain between two rows of the curve; consolidation_ratio,
    consolidation_max_steps and stress_tolerance: when consolidation has ended (the maximum
    unbalanced-force ratio below the first, every wall's stress within the last of sigma_3);
    servo_gain, servo_integral, servo_max_speed (m/s): the walls' servo; kn_wall, ks_wall
    (N/m) and friction_wall of the box (default: Table 1's stiffness and smooth walls, so
    that the walls carry normal stress only); particle_friction, rolling_friction and
    local_damping replace the specimen's when given; density_scale >= 1 scales the inertial
    masses; dt_safety the automatic time step; inertial_limit the largest inertial number
    a test may run at; smoothing_strain the window (axial strain) over which the stress ratio
    is averaged before its peak is read; critical_window the last part of the axial strain
    (a fraction of max_strain) where the critical state is read; critical_rate_limit the
    largest |d eps_v / d eps_1| over that window for it to count as critical; probe_unload
    the share of the end deviator the unloading probe takes off after shearing, the check of the
    contacts' elastic strain (None, the default: no probe; the plastic strains do not need it;
    :mod:`poro2d.biaxial.elastic`); stiffness_number, when given, the
    stiffness number kappa = kn / (sigma_3 t) the disks' kn and ks are scaled to for the test
    (:mod:`poro2d.biaxial.stiffness`; >= 1000 the rigid-grain limit; None: the specimen's);
    vtk_every (steps; 0: none) the shearing's ParaView series (:mod:`poro2d.labtest.vtk_series`),
    an output outside the test's identity, kept in the files only when asked for.
    """

    OMITTED: ClassVar[dict] = {"probe_unload": None, "stiffness_number": None, "vtk_every": 0}

    strain_rate: float | None = None
    max_strain: float = 0.20
    record_strain: float = 0.001
    consolidation_ratio: float = 1e-3
    consolidation_max_steps: int = 300_000
    stress_tolerance: float = 0.02
    servo_gain: float = 0.3
    servo_integral: float = 1e-3
    servo_max_speed: float = 0.05
    kn_wall: float = TABLE_1.kn_wall
    ks_wall: float = TABLE_1.ks_wall
    friction_wall: float = 0.0
    inertial_limit: float = 1e-3
    smoothing_strain: float = 0.01
    critical_window: float = 0.25
    critical_rate_limit: float = 0.1
    probe_unload: float | None = None
    stiffness_number: float | None = None
    vtk_every: int = outside_identity(0)

    def __post_init__(self) -> None:
        check_fields(self, BIAXIAL_RANGES)
        self.check_strains()

    def check_strains(self) -> None:
        """The curve's rows fit the test: with the rows and the window as they come, a test too short
        for them is refused as ``max_strain``, the setting that was changed (``--strain``)."""
        shortest = 3 * self.record_strain / self.critical_window
        cls = type(self)  # the class attributes are the fields' defaults
        rows_as_default = (self.record_strain, self.critical_window) == (
            cls.record_strain,
            cls.critical_window,
        )
        if rows_as_default and self.max_strain < shortest:
            raise InputError(
                "max_strain", self.max_strain, f"[{shortest:.3g}, {MAX_AXIAL_STRAIN:g}]",
                f"3 rows of the curve, one every {self.record_strain:g}, in the last {self.critical_window:g}"
                " of it",
            )  # fmt: skip
        if self.record_strain > self.max_strain:
            raise InputError("record_strain", self.record_strain, f"(0, max_strain = {self.max_strain:g}]")
        if self.max_strain / self.record_strain > MAX_RECORDS:
            shortest = self.max_strain / MAX_RECORDS
            raise InputError(
                "record_strain", self.record_strain, f"[max_strain / {MAX_RECORDS} = {shortest:.3g}, 0.05]"
            )
        if self.critical_window * self.max_strain < 3 * self.record_strain:
            raise InputError(
                "critical_window", self.critical_window,
                f"at least 3 rows of the curve: >= {3 * self.record_strain / self.max_strain:.3g}",
            )  # fmt: skip


#: the strain rate of a test whose box lets its side walls follow (1/s)
DEFAULT_STRAIN_RATE = 0.2
#: a dilating specimen widens at up to about twice its axial strain rate at the peak; each side
#: wall then moves at up to ``strain_rate * W``: the automatic rate keeps that below this share
#: of the servo's top speed, so the servo's error stays a small proportional lag
SIDE_SPEED_SHARE = 0.25


def auto_strain_rate(width_m: float, settings: BiaxialSettings) -> float:
    """The strain rate of a test in a box ``width_m`` wide: ``settings.strain_rate`` when given,
    else 0.2 /s, slowed so that each side wall's speed stays within a quarter of the servo's top.

    Measured on the paper's specimen (W 0.305 m): at 0.2 /s the side walls reach their top
    speed (0.05 m/s) near the peak and sigma_3 drifts by 44-123 %; at 0.05 /s it stays within
    2.3 % (docs/biaxial.md). The quick specimen (W 0.05 m) keeps 0.2 /s.
    """
    if settings.strain_rate is not None:
        return settings.strain_rate
    return min(DEFAULT_STRAIN_RATE, SIDE_SPEED_SHARE * settings.servo_max_speed / width_m)


def inertial_number(strain_rate: float, d50: float, rho: float, pressure_pa: float) -> float:
    """I = strain_rate * d50 * sqrt(rho / p): how far from quasi-static a test is (below 1e-3: it is).

    ``rho`` the disks' (inertial) density in kg/m3, ``p`` the mean stress in Pa.
    """
    if not pressure_pa > 0:
        return math.inf
    return strain_rate * d50 * math.sqrt(rho / pressure_pa)


__all__ = [
    "BIAXIAL_RANGES",
    "CONFINING_RANGE_KPA",
    "MIN_STRAIN_RATE",
    "PROBE_UNLOAD_RANGE",
    "STIFFNESS_NUMBER_RANGE",
    "BiaxialSettings",
    "inertial_number",
]
