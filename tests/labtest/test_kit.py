"""The laboratory-test kit: settings that are their files' table, one box and consolidation record
for both box tests, a test's line made from its result, a curve of named columns."""

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
import pytest

from poro2d.biaxial.settings import BiaxialSettings
from poro2d.errors import InputError
from poro2d.labtest.curve import ColumnCurve, CurveRow
from poro2d.labtest.records import BoxRecord, ConsolidationRecord, TestSummary
from poro2d.shear.settings import ShearSettings


def test_settings_read_back_keep_the_keys_their_file_had():
    """A file written before a setting existed reads it as None and is written back without it; a
    key of another version is written back after the settings; reading checks nothing again."""
    stored = {k: v for k, v in ShearSettings().to_dict().items() if k != "stop_after_peak"}
    stored["a_later_setting"] = 3
    read = ShearSettings.from_dict(stored)
    assert read.stop_after_peak is None and read.to_dict() == stored and list(read.to_dict()) == list(stored)
    assert ShearSettings.from_dict({**stored, "velocity": -1.0}).velocity == -1.0  # a file holds what ran
    with pytest.raises(InputError, match="velocity"):
        ShearSettings(velocity=-1.0)
    fresh = BiaxialSettings(stiffness_number=100.0).to_dict()
    assert "probe_unload" not in fresh and fresh["stiffness_number"] == 100.0
    assert BiaxialSettings.from_dict(fresh) == BiaxialSettings(stiffness_number=100.0)


def test_one_box_and_consolidation_record_write_each_tests_keys():
    split = BoxRecord(width=0.05, height=0.04, split_y=0.02, gap=0.0, max_displacement=0.01, thickness=0.008)
    assert list(split.to_dict()) == ["width", "height", "split_y", "gap", "max_displacement", "thickness"]
    plain = BoxRecord(width=0.05, height=0.1, thickness=0.008)
    assert list(plain.to_dict()) == ["width", "height", "thickness"]
    biaxial = {
        "confining_stress_kpa": 50.0, "steps": 10, "max_unbalanced_ratio": 1e-4, "sigma_1_kpa": 50.0,
        "sigma_3_left_kpa": 50.0, "sigma_3_right_kpa": 50.0, "max_stress_error": 0.01, "width_m": 0.05,
        "height_m": 0.1, "porosity": 0.2, "coordination_number": 3.9, "wall_time_s": 1.0,
        "box": plain.to_dict(),
    }  # fmt: skip
    read = ConsolidationRecord.from_dict(biaxial)
    assert (
        isinstance(read.box, BoxRecord)
        and read.to_dict() == biaxial
        and list(read.to_dict()) == list(biaxial)
    )


def test_a_summary_is_made_from_its_test_by_name():
    @dataclass(eq=False)
    class Line(TestSummary):
        label: int
        peak: float
        wall_time_s: float

    @dataclass
    class Result:
        peak: float = 31.0
        wall_time_s: float = 2.0

    assert Line.of(Result(), label=3).to_dict() == {"label": 3, "peak": 31.0, "wall_time_s": 2.0}
    assert Line.of(Result(), label=3, peak=1.0).peak == 1.0


@dataclass(frozen=True, eq=False)
class Curve(ColumnCurve):
    COLUMNS: ClassVar[tuple[str, ...]] = ("x", "y", "late")
    LATER: ClassVar[tuple[str, ...]] = ("late",)
    OPTIONAL: ClassVar[tuple[str, ...]] = ("extra",)

    x: np.ndarray
    y: np.ndarray
    late: np.ndarray
    extra: np.ndarray | None = None


@dataclass(eq=False)
class Row(CurveRow):
    x: int
    y: float
    late: float = math.nan


def test_a_column_curve_reads_rows_as_its_file_holds_them():
    """Values through float; a later column a row lacks reads as NaN, an optional one is the
    curve's only where every row has it; a column the curve must have and a row lacks: no curve."""
    curve = Curve.of_rows(
        [{"x": "1", "y": "2.5", "extra": "1"}, {"x": "2", "y": "3", "late": "4", "extra": "2"}]
    )
    assert curve.columns == ("x", "y", "late", "extra") and np.isnan(curve.late[0]) and curve.late[1] == 4.0
    assert curve.rows()[1] == {"x": 2.0, "y": 3.0, "late": 4.0, "extra": 2.0}
    assert Curve.of_rows([{"x": 1, "y": 2, "extra": ""}]).extra is None
    recorded = Curve.of_rows([Row(1, 2.0), Row.from_dict({"x": 2, "y": None})])
    assert list(recorded) == ["x", "y", "late"] and np.isnan(recorded.y[1]) and np.isnan(recorded.late).all()
    with pytest.raises(KeyError):
        Curve.of_rows([{"x": 1}])
