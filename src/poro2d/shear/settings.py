"""Settings of a direct shear test, and the inertial number that says whether it is quasi-static."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

from poro2d.dem.contact_law import MAX_ROLLING_FRICTION  # the engine's bound
from poro2d.errors import InputError, Ranges, Real, check_fields
from poro2d.identity import outside_identity
from poro2d.labtest.settings import (
    MAX_CONSOLIDATION_STEPS,
    MAX_DENSITY_SCALE,
    MAX_FRICTION,
    MAX_WALL_STIFFNESS,
    NORMAL_STRESS_RANGE_KPA,
    SERVO_AND_WALLS,
    DisksAndEngine,
    TestSettings,
    lab_ranges,
)
from poro2d.paper_data import TABLE_1
from poro2d.typed_result import with_fields

#: the longest shear displacement (m) of any test
MAX_DISPLACEMENT = 1.0
#: most rows of a test's curve, and most checkpoints, that its intervals may ask for
MAX_RECORDS = 1_000_000
MAX_CHECKPOINTS = 1000
#: a disk's normal or shear stiffness (N/m): from 1e3 (a contact of 2.5 mm disks overlaps by a
#: tenth of their diameter at 2 kPa: softer is no longer a soft-contact model) up to 1e10 (as the
#: walls; the time step falls with its square root)
PARTICLE_STIFFNESS_RANGE = (1e3, 1e10)
#: the shear velocity's range (m/s). The floor: at the quick specimen's time step (about 5e-6 s
#: with Table 1's stiffness) the default 0.02 m of shear at 1e-4 m/s takes 0.02 / (1e-4 x 5e-6)
#: = 4e7 steps, four times the consolidation's largest budget (MAX_CONSOLIDATION_STEPS): days of
#: one core, as biaxial's MIN_STRAIN_RATE. A slower test would not end in any run's time and is
#: refused before any work
MIN_VELOCITY = 1e-4
MAX_VELOCITY = 10.0


#: what each setting of :class:`ShearSettings` may be (checked in this order); the intervals
#: are checked against ``max_displacement`` and ``stop_after_peak`` against ``peak_window``
#: after these
SHEAR_RANGES: Ranges = {
    "velocity": Real(MIN_VELOCITY, MAX_VELOCITY),
    # half the width of a 2 m box; a test checks it against its own specimen's half width too
    "max_displacement": Real(0.0, MAX_DISPLACEMENT, lo_open=True),
    "record_interval": Real(0.0, None, lo_open=True),
    # beyond max_displacement it never ends a test (as a short quick test with the default)
    "stop_after_peak": Real(0.0, MAX_DISPLACEMENT),
    "checkpoint_interval": Real(0.0, None, lo_open=True),
    **lab_ranges("consolidation_ratio", "consolidation_max_steps", *SERVO_AND_WALLS),
    "gap": Real(0.0, None),
    **lab_ranges("particle_friction", "rolling_friction"),
    "particle_kn": Real(*PARTICLE_STIFFNESS_RANGE, or_none=True),
    "particle_ks": Real(*PARTICLE_STIFFNESS_RANGE, or_none=True),
    **lab_ranges("local_damping", "density_scale", "dt_safety"),
    "peak_window": Real(0.0, None),
    "shear_zone_factor": Real(0.0, None, lo_open=True),
    "inertial_limit": Real(0.0, None, lo_open=True),
    **lab_ranges("stress_tolerance", "vtk_every"),
}


@dataclass
@with_fields(DisksAndEngine, after="gap")
class ShearSettings(TestSettings):
    """Settings of a direct shear test (SI units; the box walls default to Table 1), also the
    ``settings`` its files keep (:class:`~poro2d.labtest.settings.TestSettings`).

    velocity (m/s) and max_displacement (m) of the lower half; stop_after_peak (m): the
    test ends once the smoothed peak lies that far behind (0: always run to
    max_displacement); record_interval and
    checkpoint_interval (m of shear displacement); consolidation_ratio and
    consolidation_max_steps for the consolidation stage; servo_gain, servo_integral
    (per step; it keeps the stress on target while the specimen dilates) and
    servo_max_speed (m/s) of the top plate; kn_wall, ks_wall (N/m), friction_wall and
    gap (m) of the box; particle_friction replaces the specimen's when given;
    rolling_friction likewise replaces every disk's rolling friction mu_r (None: the
    specimen's own), and the box walls take the disks' largest mu_r;
    local_damping likewise (None: the specimen's); particle_kn and particle_ks (N/m) replace
    every disk's normal and shear stiffness (None: the specimen's; the time step follows the
    stiffness used, a stiffer disk a shorter one); density_scale >= 1 scales the
    inertial masses; dt_safety the automatic time step; peak_window (m) the
    smoothing of the peak; shear_zone_factor k in gamma_dot = v / (k d_mean);
    inertial_limit and stress_tolerance the quasi-static and servo checks.

    Its files hold every setting in this order; the disks' stiffnesses ``particle_kn`` and
    ``particle_ks`` only when given, so a test on the specimen's own stiffness keeps the file,
    and the cache key, it had before they existed. ``vtk_every`` (steps; 0: none) asks for the
    shear stage's ParaView series (:mod:`poro2d.labtest.vtk_series`): an output, outside the
    test's identity, kept in the files only when asked for.
    """

    OMITTED: ClassVar[dict] = {"particle_kn": None, "particle_ks": None, "vtk_every": 0}

    velocity: float = 0.025
    max_displacement: float = 0.02
    stop_after_peak: float = 0.005
    record_interval: float = 5e-5
    checkpoint_interval: float = 1e-3
    consolidation_ratio: float = 1e-3
    consolidation_max_steps: int = 300_000
    servo_gain: float = 0.5
    servo_integral: float = 1e-3
    servo_max_speed: float = 0.05
    kn_wall: float = TABLE_1.kn_wall
    ks_wall: float = TABLE_1.ks_wall
    friction_wall: float = TABLE_1.friction_wall
    gap: float = 0.0
    peak_window: float = 2e-3
    shear_zone_factor: float = 10.0
    inertial_limit: float = 1e-3
    stress_tolerance: float = 0.02
    particle_kn: float | None = None
    particle_ks: float | None = None
    vtk_every: int = outside_identity(0)

    def __post_init__(self) -> None:
        check_fields(self, SHEAR_RANGES)
        # at most MAX_RECORDS rows and MAX_CHECKPOINTS checkpoints a test: a finer interval
        # (1e-300 m) asks for more rows than memory holds, or a checkpoint every step
        self._check_interval("record_interval", self.record_interval, MAX_RECORDS)
        self._check_interval("checkpoint_interval", self.checkpoint_interval, MAX_CHECKPOINTS)
        if 0.0 < self.stop_after_peak < self.peak_window:
            # the smoothed value at a peak needs half a window of curve after it to be final
            allowed = f"0 (off) or >= peak_window = {self.peak_window} m"
            raise InputError("stop_after_peak", self.stop_after_peak, allowed)
        if self.record_interval > self.max_displacement:
            raise InputError("record_interval", self.record_interval, f"(0, {self.max_displacement}] m")

    def _check_interval(self, name: str, interval: float, most: int) -> None:
        """An interval of shear displacement (m) that comes at most ``most`` times a test."""
        shortest = self.max_displacement / most
        if interval < shortest:
            raise InputError(name, interval, f"[max_displacement / {most} = {shortest:.3g}, inf) m")


def half_velocity(velocity: float) -> float:
    """The rate check's rerun velocity, half of ``velocity`` (m/s).

    Refused, naming the velocity the user gave, when the half falls below :data:`MIN_VELOCITY`:
    the rerun would be a test too slow to end, and the user's velocity alone is allowed.
    """
    half = 0.5 * velocity
    if half < MIN_VELOCITY:
        allowed = f"[{2 * MIN_VELOCITY:g}, {MAX_VELOCITY:g}] m/s with the rate check"
        hint = f"its rerun at half the velocity, {half:g} m/s, would be below the floor {MIN_VELOCITY:g} m/s"
        raise InputError("velocity", velocity, allowed, hint)
    return half


def inertial_number(velocity: float, sigma_pa: float, rho_inertial: float, shear_zone_factor: float) -> float:
    """I = gamma_dot d_mean sqrt(rho / sigma_n) with gamma_dot = v / (k d_mean).

    The shear zone of a direct shear test is about 10 to 20 mean diameters thick;
    taking k = 10 (the thin end) over-estimates the shear rate, so I is on the safe
    side. With this estimate d_mean cancels: I = (v / k) sqrt(rho / sigma_n).
    """
    if not sigma_pa > 0:
        return math.inf
    return velocity / shear_zone_factor * math.sqrt(rho_inertial / sigma_pa)


__all__ = [
    "MAX_CONSOLIDATION_STEPS",
    "MAX_DENSITY_SCALE",
    "MAX_FRICTION",
    "MAX_ROLLING_FRICTION",
    "MAX_VELOCITY",
    "MAX_WALL_STIFFNESS",
    "MIN_VELOCITY",
    "NORMAL_STRESS_RANGE_KPA",
    "PARTICLE_STIFFNESS_RANGE",
    "ShearSettings",
    "half_velocity",
    "inertial_number",
]
