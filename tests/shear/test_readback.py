"""A stored test's result is checked against its curve when read back (poro2d.shear.curve.contradiction)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from poro2d.shear.curve import CURVE_COLUMNS, LATER_COLUMNS, contradiction, curve_columns

WINDOW = 5e-4  # m


def _rows(n: int = 40) -> list[dict]:
    """Rows of a curve rising to a peak near 1.2 mm, then softening (displacement mm, stress kPa)."""
    d = np.linspace(0.05, 2.0, n)
    tau = 60.0 * d * np.exp(1.0 - d / 1.2) / 1.2
    rows = [dict.fromkeys(CURVE_COLUMNS, 1.0) for _ in range(n)]
    for k, row in enumerate(rows):
        row.update(step=float(100 * k), shear_displacement_mm=d[k], shear_stress_kpa=tau[k])
        for name in LATER_COLUMNS:
            row[name] = math.nan  # a curve of an earlier version: still readable
    return rows


def _curve():
    return curve_columns(_rows())


def _result(curve, **changes) -> dict:
    """The values a result.json holds of ``curve``, computed here by hand (the smoothed maximum)."""
    x, tau = curve.shear_displacement_mm * 1e-3, curve.shear_stress_kpa
    smooth = np.array([tau[np.abs(x - xi) <= WINDOW / 2].mean() for xi in x])
    result = {"records": len(x), "peak_shear_stress_kpa": float(smooth.max()),
              "end": {"shear_stress_kpa": float(smooth[-1])}}  # fmt: skip
    result.update(changes)
    return result


def test_a_result_that_its_curve_records_is_used():
    curve = _curve()
    assert contradiction(_result(curve), curve, WINDOW) is None


@pytest.mark.parametrize(
    ("changes", "words"),
    [
        ({"peak_shear_stress_kpa": 150.0}, "peak_shear_stress_kpa is 150"),
        ({"peak_shear_stress_kpa": math.nan}, "peak_shear_stress_kpa is nan"),
        ({"peak_shear_stress_kpa": None}, "peak_shear_stress_kpa is None"),
        ({"end": {"shear_stress_kpa": 1.0}}, "end shear_stress_kpa is 1"),
        ({"end": None}, "end shear_stress_kpa is None"),
        ({"records": 39}, "records is 39"),
    ],
)
def test_a_result_that_differs_from_its_curve_is_not(changes, words):
    curve = _curve()
    assert words in contradiction(_result(curve, **changes), curve, WINDOW)


def test_a_missing_or_broken_curve_is_not_used():
    curve = _curve()
    result = _result(curve)
    assert contradiction(result, None, WINDOW) == "curve.csv is missing"
    rows = _rows()
    rows[7]["shear_stress_kpa"] = math.inf
    broken = curve_columns(rows)
    assert "not finite" in contradiction(result, broken, WINDOW)
    assert contradiction(result, curve_columns(_rows()[:-1]), WINDOW)  # cut short by a record
