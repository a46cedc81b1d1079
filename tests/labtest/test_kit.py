"""The laboratory-test kit: settings that are their files' table, one box and consolidation record
for both box tests, a test's line made from its result, a curve of named columns, the one settle
loop and a result's parts read off its fields."""

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
import pytest

from poro2d.biaxial.settings import BiaxialSettings
from poro2d.dem.reporters import drive_blocks
from poro2d.errors import InputError
from poro2d.labtest.curve import ColumnCurve, CurveRow
from poro2d.labtest.records import BoxRecord, ByName, ConsolidationRecord, TestSummary, typed_parts
from poro2d.labtest.settle import AtEquilibrium, Settled, settle, settle_until
from poro2d.shear.settings import ShearSettings
from poro2d.typed_result import TypedResult


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


class Clock:
    """A stand-in simulation for the settle loop: steps a counter, its reporters due after each block."""

    def __init__(self, step_count=0):
        self.step_count = step_count
        self.ratio = 1.0

    def run(self, steps, *, reporters, progress=False):
        return type("Ran", (), {"steps": drive_blocks(self.advance, steps, reporters, self)})()

    def advance(self, n):
        self.step_count, self.ratio = self.step_count + n, self.ratio / 2.0
        return n, False

    def unbalanced_ratios(self):
        return (self.ratio,)

    def reset_clock(self):
        self.step_count = 0


def test_one_settle_loop_runs_until_its_stop_rule_says_settled():
    """settle_until counts its own steps and tells progress its share; AtEquilibrium, the box tests'
    rule, renews the servos while it has not settled and keeps the last ratio and error."""
    sim, seen = Clock(step_count=1000), []
    steps = settle_until(sim, lambda sm: sm.step_count >= 1300, 1000, every=100,
                         progress=lambda phase, f: seen.append((phase, f)), phase="probing")  # fmt: skip
    assert steps == 300 and seen == [("probing", 0.1), ("probing", 0.2), ("probing", 0.3)]
    renewed = []
    end = settle(Clock(step_count=7), lambda sm: 0.0, ratio_limit=0.1, tolerance=0.01, max_steps=10_000,
                 every=100, renew=renewed.append)  # fmt: skip
    assert end == Settled(400, 0.0625, 0.0, True) and len(renewed) == 3
    never = AtEquilibrium(lambda sm: 1.0, ratio_limit=0.1, tolerance=0.01)
    assert settle_until(Clock(), never, 250, every=100) == 250 and not never.reached


def test_a_results_parts_are_its_fields_types_and_it_is_made_from_its_reading_by_name():
    @typed_parts
    @dataclass(eq=False)
    class Reading(TypedResult):
        peak: float
        box: BoxRecord

    @typed_parts
    @dataclass(eq=False)
    class Result(ByName, Reading):
        boxes: list[BoxRecord]
        consolidation: ConsolidationRecord | None = None
        label: str = ""

    assert Result.PARTS == {"box": BoxRecord, "boxes": BoxRecord, "consolidation": ConsolidationRecord}
    box = BoxRecord(width=0.05, height=0.1, thickness=0.008)
    made = Result.of(Reading(31.0, box), boxes=[box])
    assert list(made.to_dict()) == ["peak", "box", "boxes", "consolidation", "label"]
    back = Result.from_dict(made.to_dict())
    assert back == made and isinstance(back.box, BoxRecord) and isinstance(back.boxes[0], BoxRecord)


def test_a_curve_class_made_of_its_rows_declares_its_columns_once():
    """curve_of: the row's fields are the curve's columns, in order; later ones read as NaN, optional
    ones (the row's and the curve's own) last, None where not given."""
    from poro2d.labtest.curve import curve_of

    made = curve_of(Row, "Made", __name__, later=("late",), optional=("more",))
    assert made.COLUMNS == ("x", "y", "late") and made.OPTIONAL == ("more",)
    curve = made.of_rows([Row(1, 2.0)])
    assert curve.columns == ("x", "y", "late") and np.isnan(curve.late[0]) and curve.more is None
