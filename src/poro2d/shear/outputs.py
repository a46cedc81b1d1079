"""The files of a direct shear series: test folders, curves and peaks tables (Fig. 8 is drawn from
the result by ``report/shear_figures.py``)."""

from __future__ import annotations

from collections.abc import Mapping

from poro2d.shear.curve import CURVE_COLUMNS, ShearCurve
from poro2d.shear.fit import MohrCoulombFit, mohr_coulomb
from poro2d.shear.lab import LabData
from poro2d.shear.parts import ShearTestSummary
from poro2d.store import Store


def folder_name(sigma_kpa: float) -> str:
    """The folder of the test at ``sigma_kpa`` in a series' output (``sn100kPa``)."""
    return f"sn{sigma_kpa:g}kPa"


def lab_fit(lab: LabData | None) -> MohrCoulombFit | None:
    """The Mohr-Coulomb line through the laboratory peaks (None with fewer than two)."""
    if lab is None or len(lab.peaks) < 2:
        return None
    ls = lab.normal_stresses()
    return mohr_coulomb(ls, [lab.peaks[v] for v in ls])


def write_tables(store: Store, curves: dict[float, ShearCurve], summary: list[ShearTestSummary]) -> None:
    """``curves.csv`` (every curve, long format) and ``peaks.csv`` (one row per test).

    ``curves``: each test's curve (:attr:`ShearTestResult.curve`) by normal stress.
    """
    long_rows = [
        {"normal_stress_kpa": sigma, **row} for sigma, curve in curves.items() for row in curve.rows()
    ]
    store.write_csv("curves.csv", long_rows, header=["normal_stress_kpa"] + CURVE_COLUMNS)
    # the nested parts of a test's summary (end values, force balance) are in result.json only
    store.write_csv(
        "peaks.csv", [{k: v for k, v in r.to_dict().items() if not isinstance(v, Mapping)} for r in summary]
    )


__all__ = ["folder_name", "lab_fit", "write_tables"]
