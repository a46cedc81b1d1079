"""The time series of a periodic shear run: one row per ``record_strain`` of shear strain.

Each row holds the means over the steps since the previous row: stresses from the
Love-Weber contact sum plus the kinetic part (kPa, compression positive for the normal
stresses, the shear stress tau = sigma_xy with the sign that makes the stress ratio
tau / sigma_yy positive in the direction of shearing), the solid fraction, the inertial
number actually reached, I = gamma_dot d sqrt(rho / sigma_yy), and the coordination 2 N_c / N.
The fabric (:class:`~poro2d.measure.fabric.Fabric`: anisotropies, mechanical coordination) is
the cell's at the row's end, not a mean: the last columns, NaN in a series of an earlier poro2d.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from poro2d.labtest.curve import ColumnCurve
from poro2d.measure.fabric import FABRIC_COLUMNS, Fabric

#: the columns of ``series.csv``, in the order of :class:`CellSeries`' fields
COLUMNS = (
    "gamma",
    "stress_ratio",
    "normal_stress_kpa",
    "shear_stress_kpa",
    "mean_stress_kpa",
    "solid_fraction",
    "inertial_number",
    "coordination",
    *FABRIC_COLUMNS,
)


@dataclass(frozen=True, eq=False)
class CellSeries(ColumnCurve):
    """The rows of a run as arrays (one entry per row), a curve of the columns of ``series.csv``."""

    COLUMNS: ClassVar[tuple[str, ...]] = COLUMNS
    LATER: ClassVar[tuple[str, ...]] = FABRIC_COLUMNS

    gamma: np.ndarray
    stress_ratio: np.ndarray
    normal_stress_kpa: np.ndarray
    shear_stress_kpa: np.ndarray
    mean_stress_kpa: np.ndarray
    solid_fraction: np.ndarray
    inertial_number: np.ndarray
    coordination: np.ndarray
    # the fabric (LATER): NaN where not given
    a_c: np.ndarray | None = None
    theta_c: np.ndarray | None = None
    a_n: np.ndarray | None = None
    theta_n: np.ndarray | None = None
    a_t: np.ndarray | None = None
    theta_t: np.ndarray | None = None
    z_mech: np.ndarray | None = None
    rattler_fraction: np.ndarray | None = None

    def __post_init__(self) -> None:
        for name in FABRIC_COLUMNS:
            if getattr(self, name) is None:
                object.__setattr__(self, name, np.full(len(self.gamma), np.nan))

    def window(self, start: float) -> np.ndarray:
        """The rows at gamma >= start (a boolean mask)."""
        return self.gamma >= start


def row_of(
    gamma: float, block, shear_rate: float, d_mean: float, density: float, fabric: Fabric
) -> dict[str, float]:
    """A row from a block of the cell (:class:`poro2d.dem.periodic.CellBlock`) and its fabric now."""
    s = block.stress
    syy = -float(s[1, 1])
    inertial = shear_rate * d_mean * float(np.sqrt(density / syy)) if syy > 0.0 else float("inf")
    return {
        "gamma": gamma,
        "stress_ratio": block.stress_ratio,
        "normal_stress_kpa": syy / 1e3,
        "shear_stress_kpa": float(s[0, 1]) / 1e3,
        "mean_stress_kpa": -0.5 * float(s[0, 0] + s[1, 1]) / 1e3,
        "solid_fraction": block.solid_fraction,
        "inertial_number": inertial,
        "coordination": block.coordination,
        **fabric.row(),
    }


__all__ = ["COLUMNS", "CellSeries", "row_of"]
