"""The criterion's settings: the thresholds of Fig. 3 and the plate servo, checked once.

A run is made with them and its result keeps them (``result.json``'s ``settings``, read back
by :meth:`CriterionSettings.from_dict`): one class for both.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Any, ClassVar

from poro2d.errors import Integer, OneOf, Ranges, Real, check_fields, check_range
from poro2d.identity import outside_identity
from poro2d.labtest.settings import lab_ranges
from poro2d.porosity import PAPER_N_LAB, parabolic
from poro2d.record import Record

#: how a trial's specimen is judged full: "plate", the paper's rigid top plate (its n' includes
#: the gap under the plate); "fill", a segmented lid that rests on the grains over the width
#: (:mod:`poro2d.criterion.lid`; n' is the porosity of the box the specimen fills)
ACCEPTANCE_MODES = ("plate", "fill")

#: what each setting of :class:`CriterionSettings` may be (checked in this order);
#: ``refine_tolerance`` is checked against ``porosity_tolerance`` after these
CRITERION_RANGES: Ranges = {
    "n_lab": Real(0.0, 1.0, hi_open=True),
    "trial_porosity": Real(0.0, 1.0, lo_open=True, hi_open=True, or_none=True),
    "force_fraction": Real(0.0, 1.0, lo_open=True),
    "porosity_tolerance": Real(0.0, 0.1, lo_open=True),
    "resolution": Real(0.0, 0.1, lo_open=True),
    "max_iterations": Integer(1, 50),
    "servo_target_fraction": Real(0.0, 1.0, lo_open=True, hi_open=True),
    "servo_max_speed": Real(0.0, 10.0, lo_open=True),
    "servo_gain": Real(0.0, 1.0, lo_open=True),
    "settle_gain": Real(0.0, 1.0, lo_open=True),
    "settle_max_speed": Real(0.0, 10.0, lo_open=True),
    "plate_drift": Real(0.0, 0.1, lo_open=True),
    "settle_checks": Integer(2),
    "max_plate_steps": Integer(1000),
    "check_every": Integer(1),
    "window_checks": Integer(1),
    "generation_tolerance": Real(0.0, 0.05, lo_open=True),
    "balance_tolerance": Real(0.0, 0.5, lo_open=True),
    "acceptance": OneOf(ACCEPTANCE_MODES),
    **lab_ranges("vtk_every"),
}


@dataclass
class CriterionSettings(Record):
    """Thresholds of Fig. 3 (the paper's values by default) and the plate servo.

    Its row (:meth:`~poro2d.record.Record.to_dict`) is the settings as recorded with results:
    ``refine_tolerance`` only when set and ``acceptance`` only when not "plate", so folders
    written before the options existed still resume. ``vtk_every`` (steps; 0: none): each trial's
    plate stage as a ParaView series (:mod:`poro2d.labtest.vtk_series`), an output outside the
    run's identity, recorded only when asked for.
    """

    OMITTED: ClassVar[dict[str, Any]] = {"refine_tolerance": None, "acceptance": "plate", "vtk_every": 0}

    n_lab: float = PAPER_N_LAB
    trial_porosity: float | None = None
    force_fraction: float = 0.01
    porosity_tolerance: float = 0.005
    resolution: float = 0.01
    max_iterations: int = 6
    servo_target_fraction: float = 0.5
    servo_max_speed: float = 0.05
    servo_gain: float = 0.3
    settle_gain: float = 0.02
    settle_max_speed: float = 0.001
    settle_checks: int = 20
    plate_drift: float = 1e-4
    max_plate_steps: int = 600_000
    check_every: int = 500
    window_checks: int = 4
    generation_tolerance: float = 1e-3
    balance_tolerance: float = 0.01
    refine_tolerance: float | None = None
    acceptance: str = "plate"
    vtk_every: int = outside_identity(0)

    @classmethod
    def from_dict(cls, row: dict[str, Any]) -> CriterionSettings:
        """The settings of a row (a result's ``settings``, a config record's ``criterion``): a key
        the row lacks takes its default, as it was when the row was written."""
        return cls(**{f.name: row[f.name] for f in fields(cls) if f.name in row})

    def __post_init__(self) -> None:
        check_fields(self, CRITERION_RANGES)
        if self.refine_tolerance is not None:
            check_range("refine_tolerance", self.refine_tolerance, 1e-4, self.porosity_tolerance)

    @property
    def tolerance(self) -> float:
        """|n' - n2D| below this accepts a trial: the paper's 0.005, or ``refine_tolerance``."""
        return self.porosity_tolerance if self.refine_tolerance is None else self.refine_tolerance

    def initial_trial(self) -> float:
        """Eq. 12 (n2D = 0.42 nLab^2 + 0.25 nLab), rounded to the resolution, unless given."""
        if self.trial_porosity is not None:
            return float(self.trial_porosity)
        return round_to(float(parabolic(self.n_lab)), self.resolution)


def round_to(x: float, step: float) -> float:
    return round(round(x / step) * step, 10)


__all__ = ["ACCEPTANCE_MODES", "CRITERION_RANGES", "CriterionSettings", "round_to"]
