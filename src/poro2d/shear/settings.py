"""Settings of a direct shear test, and the inertial number that says whether it is quasi-static."""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

from poro2d.dem.contact_law import MAX_ROLLING_FRICTION as ENGINE_MAX_ROLLING_FRICTION
from poro2d.errors import InputError, Integer, Ranges, Real, check_fields
from poro2d.paper_data import TABLE_1
from poro2d.shear.parts import ShearSettingsRecord

#: the normal stresses (kPa) a test may be run at. A contact carries about sigma d t, so two
#: disks of the paper's stiffness (kn = 4e5 N/m each, in series 2e5; 8 mm thick) overlap by
#: sigma t / k = 4 % of their diameter at 1 MPa, and more above: beyond what a soft-contact
#: model describes. Below 1 kPa the plate pushes less than the specimen's own weight does at
#: mid-height (about 1.3 kPa in the paper's box), so the stress held is not the one the shear
#: plane feels. docs/shear.md has the reasoning.
NORMAL_STRESS_RANGE_KPA = (1.0, 1000.0)
#: the longest shear displacement (m) of any test
MAX_DISPLACEMENT = 1.0
#: most rows of a test's curve, and most checkpoints, that its intervals may ask for
MAX_RECORDS = 1_000_000
MAX_CHECKPOINTS = 1000
#: 30 times the default step budget of the consolidation (hours of one core for the paper's box)
MAX_CONSOLIDATION_STEPS = 10_000_000
#: wall stiffness (N/m): 1000 times Table 1's; the time step falls with its square root
MAX_WALL_STIFFNESS = 1e10
#: friction coefficients beyond 10 hold as a rough wall does; larger ones are typos
MAX_FRICTION = 10.0
#: a disk's normal or shear stiffness (N/m): from 1e3 (a contact of 2.5 mm disks overlaps by a
#: tenth of their diameter at 2 kPa: softer is no longer a soft-contact model) up to 1e10 (as the
#: walls; the time step falls with its square root)
PARTICLE_STIFFNESS_RANGE = (1e3, 1e10)
#: the largest rolling friction (the engine's bound, see poro2d.dem.contact_law)
MAX_ROLLING_FRICTION = ENGINE_MAX_ROLLING_FRICTION
#: inertial masses up to 1000 times the real ones: the inertial number grows with its root
MAX_DENSITY_SCALE = 1000.0


#: what each setting of :class:`ShearSettings` may be (checked in this order); the intervals
#: are checked against ``max_displacement`` and ``stop_after_peak`` against ``peak_window``
#: after these
SHEAR_RANGES: Ranges = {
    "velocity": Real(0.0, 10.0, lo_open=True),
    # half the width of a 2 m box; a test checks it against its own specimen's half width too
    "max_displacement": Real(0.0, MAX_DISPLACEMENT, lo_open=True),
    "record_interval": Real(0.0, None, lo_open=True),
    # beyond max_displacement it never ends a test (as a short quick test with the default)
    "stop_after_peak": Real(0.0, MAX_DISPLACEMENT),
    "checkpoint_interval": Real(0.0, None, lo_open=True),
    "consolidation_ratio": Real(0.0, 1.0, lo_open=True),
    "consolidation_max_steps": Integer(1000, MAX_CONSOLIDATION_STEPS),
    "servo_gain": Real(0.0, 1.0, lo_open=True),
    "servo_integral": Real(0.0, 0.1),
    "servo_max_speed": Real(0.0, 10.0, lo_open=True),
    "kn_wall": Real(0.0, MAX_WALL_STIFFNESS, lo_open=True),
    "ks_wall": Real(0.0, MAX_WALL_STIFFNESS),
    "friction_wall": Real(0.0, MAX_FRICTION),
    "gap": Real(0.0, None),
    "particle_friction": Real(0.0, MAX_FRICTION, or_none=True),
    "rolling_friction": Real(0.0, MAX_ROLLING_FRICTION, or_none=True),
    "particle_kn": Real(*PARTICLE_STIFFNESS_RANGE, or_none=True),
    "particle_ks": Real(*PARTICLE_STIFFNESS_RANGE, or_none=True),
    "local_damping": Real(0.0, 1.0, hi_open=True, or_none=True),
    "density_scale": Real(1.0, MAX_DENSITY_SCALE),
    "dt_safety": Real(0.0, 1.0, lo_open=True),
    "peak_window": Real(0.0, None),
    "shear_zone_factor": Real(0.0, None, lo_open=True),
    "inertial_limit": Real(0.0, None, lo_open=True),
    "stress_tolerance": Real(0.0, 1.0, lo_open=True),
}


@dataclass
class ShearSettings:
    """Settings of a direct shear test (SI units; the box walls default to Table 1).

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
    """

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
    particle_friction: float | None = None
    rolling_friction: float | None = None
    local_damping: float | None = None
    density_scale: float = 1.0
    dt_safety: float = 0.8
    peak_window: float = 2e-3
    shear_zone_factor: float = 10.0
    inertial_limit: float = 1e-3
    stress_tolerance: float = 0.02
    particle_kn: float | None = None
    particle_ks: float | None = None

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

    def record(self) -> ShearSettingsRecord:
        """The settings as a result file keeps them (every setting, in this class's order)."""
        return ShearSettingsRecord(**{f.name: getattr(self, f.name) for f in fields(self)})


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
    "MAX_ROLLING_FRICTION",
    "NORMAL_STRESS_RANGE_KPA",
    "PARTICLE_STIFFNESS_RANGE",
    "ShearSettings",
    "inertial_number",
]
