"""The typed parts of the direct shear results read from files of earlier versions, written back the same."""

import dataclasses
import json
import math
import pickle
from pathlib import Path

import numpy as np

from poro2d.labtest.records import ConsolidationRecord
from poro2d.shear.curve import CURVE_COLUMNS, ShearCurve, ShearRow, curve_columns
from poro2d.shear.fit import mohr_coulomb, peak
from poro2d.shear.parts import (
    EndValues,
    FitInterval,
    ForceBalance,
    LabComparison,
    MohrCoulombFit,
    QuasiStatic,
    RateCheck,
    RateCheckRow,
    ShearTestSummary,
    StressPeaks,
)
from poro2d.shear.replicates import mohr_coulomb_ci
from poro2d.shear.results import ReplicateShearResult, ShearSeriesResult, ShearTestResult

DATA = Path(__file__).parents[1] / "data" / "before_typed_results"


def _stored(name: str) -> dict:
    return json.loads((DATA / name).read_text())


def test_a_test_result_reads_into_its_parts():
    stored = _stored("shear_test_result.json")
    r = ShearTestResult.from_dict(stored)
    assert isinstance(r.end, EndValues) and isinstance(r.force_balance, ForceBalance)
    assert isinstance(r.consolidation, ConsolidationRecord) and "engine" not in r.consolidation.to_dict()
    assert r.end.shear_stress_kpa == stored["end"]["shear_stress_kpa"]
    assert r.to_dict() == stored and json.loads(json.dumps(r.to_dict())) == stored
    assert list(r.to_dict()["consolidation"]) == list(stored["consolidation"])  # the file's order


def test_a_series_result_reads_into_its_parts():
    stored = _stored("shear_series_result.json")
    s = ShearSeriesResult.from_dict(stored)
    assert all(isinstance(t, ShearTestSummary) and isinstance(t.end, EndValues) for t in s.tests)
    assert isinstance(s.fit, MohrCoulombFit) and isinstance(s.fit_through_origin, MohrCoulombFit)
    assert isinstance(s.quasi_static, QuasiStatic) and isinstance(s.lab, LabComparison)
    assert isinstance(s.rate_check, RateCheck) and all(
        isinstance(t, RateCheckRow) for t in s.rate_check.tests
    )
    assert s.tests[0].end.to_dict() == stored["tests"][0]["end"]  # a part writes the dict it was read from
    assert json.loads(json.dumps(s.to_dict())) == stored
    assert pickle.loads(pickle.dumps(s)).to_dict() == stored


def test_a_replicate_result_reads_into_its_parts():
    stored = _stored("shear_replicates.json")
    r = ReplicateShearResult.from_dict(stored)
    assert all(isinstance(p, StressPeaks) for p in r.per_normal_stress)
    assert isinstance(r.fit, FitInterval) and isinstance(r.fit_through_origin, FitInterval)
    assert r.fit_through_origin.cohesion_ci_kpa is None
    assert json.loads(json.dumps(r.to_dict())) == stored


def test_fits_are_kept_as_their_dicts_were():
    s, t = [50.0, 100.0, 200.0], [40.0, 76.0, 139.0]
    fit = mohr_coulomb(s, t)
    named = {f.name: getattr(fit, f.name) for f in dataclasses.fields(fit) if f.name != "extra"}
    assert fit.to_dict() == named
    assert fit.tan_phi == math.tan(math.radians(fit.friction_angle_deg))
    ci = mohr_coulomb_ci(s, t)
    assert list(ci.to_dict()) == [
        *fit.to_dict(),
        "level",
        "dof",
        "friction_angle_ci_deg",
        "cohesion_ci_kpa",
    ]
    lo, hi = ci.friction_angle_ci_deg
    assert lo < ci.friction_angle_deg < hi and ci.dof == 1


def test_a_curve_row_is_a_record_of_the_files_columns():
    assert [f.name for f in dataclasses.fields(ShearRow) if f.name != "extra"] == CURVE_COLUMNS
    row = ShearRow(*range(len(CURVE_COLUMNS)))
    assert (
        list(row.to_dict()) == CURVE_COLUMNS and {k: getattr(row, k) for k in CURVE_COLUMNS} == row.to_dict()
    )
    assert ShearRow.from_dict(json.loads(json.dumps(row.to_dict()))).to_dict() == row.to_dict()


def test_a_curve_is_its_columns():
    rows = [{k: float(i + j) for j, k in enumerate(CURVE_COLUMNS)} for i in range(4)]
    curve = curve_columns(rows)
    assert isinstance(curve, ShearCurve) and list(curve) == CURVE_COLUMNS and len(curve) == len(CURVE_COLUMNS)
    np.testing.assert_array_equal(curve.shear_stress_kpa, curve["shear_stress_kpa"])
    assert curve.rows() == rows and curve_columns([]) is None
    k, x, value = peak(curve.shear_displacement_mm, curve.shear_stress_kpa, 0.0)
    assert peak(curve.shear_displacement_mm, curve.shear_stress_kpa, 0.0).index == k == 3 and value == x + 1
