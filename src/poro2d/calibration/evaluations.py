"""A calibration's evaluations: each design point with its observables' replicate values.

``result.json`` keeps one row per design point (``evaluations``): the parameter pair, then a
key per laboratory target (``peak_50kPa``, ``end_100kPa``, ``dilation_50kPa``) with the value of
each replicate specimen (kPa for the stresses, mm for the dilation). The targets vary with the
laboratory data, so the keys are formed from them (:func:`target_key`) and read back into the
observable and stress they name.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from poro2d.record import Record, Spliced

#: the key of each calibrated parameter (an axis of :mod:`poro2d.calibration.model`) in the files
PARAMETER_KEYS = {
    "fp": "particle_friction",
    "mu_r": "rolling_friction",
    "kn": "particle_kn",
    "ks": "particle_ks",
}


def target_key(observable: str, normal_stress_kpa: float) -> str:
    """How a file names an observable at a normal stress (``peak_50kPa``): in ``evaluations`` and ``fit``."""
    return f"{observable}_{normal_stress_kpa:g}kPa"


@dataclass(frozen=True)
class Observed(Record):
    """One observable of a design point at one normal stress: its value per replicate specimen
    (in the specimens' order; NaN where the test failed; kPa for a stress, mm for the dilation),
    written under :func:`target_key`."""

    observable: str
    normal_stress_kpa: float
    values: list[float]

    def layout(self) -> tuple:
        return ((target_key(self.observable, self.normal_stress_kpa), "values"),)

    @classmethod
    def from_key(cls, key: str, values: list[float]) -> Observed:
        """The observable a file's key names (``peak_50kPa``), with its values."""
        observable, _, stress = key.rpartition("_")
        if not observable or not stress.endswith("kPa"):
            raise ValueError(f"not an observable at a normal stress: {key!r}")
        return cls(observable, float(stress.removesuffix("kPa")), values)


@dataclass(frozen=True, eq=False)
class DesignPoint(Record):
    """One evaluated design point (a row of ``evaluations``): the parameter pair (and the disks'
    stiffnesses ``particle_kn``, ``particle_ks`` in N/m when they are calibrated: absent from the
    row otherwise), then each observable's replicate values in the order of the laboratory targets.

    Its row (:meth:`~poro2d.record.Record.to_dict`) is the file's; its values are read by
    attribute (``point.observed``).
    """

    ROW = ("particle_friction", "rolling_friction", "particle_kn", "particle_ks", Spliced("observed"))
    OMITTED = {"particle_kn": None, "particle_ks": None}

    particle_friction: float
    rolling_friction: float
    observed: tuple[Observed, ...]
    particle_kn: float | None = None
    particle_ks: float | None = None

    @classmethod
    def from_dict(cls, row: Mapping[str, Any]) -> DesignPoint:
        """A design point from its row in a file: every key beside the pair is an observable."""
        observed = tuple(Observed.from_key(k, v) for k, v in row.items() if k not in cls.ROW)
        stiffness = {k: row[k] for k in ("particle_kn", "particle_ks") if k in row}
        return cls(row["particle_friction"], row["rolling_friction"], observed, **stiffness)

    def parameters(self, axes: tuple[str, ...]) -> tuple[float, ...]:
        """The point's values of the calibrated parameters ``axes`` (:data:`PARAMETER_KEYS`' keys)."""
        return tuple(getattr(self, PARAMETER_KEYS[a]) for a in axes)


__all__ = ["PARAMETER_KEYS", "DesignPoint", "Observed", "target_key"]
