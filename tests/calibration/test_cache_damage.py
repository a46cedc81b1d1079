"""A damaged cached shear test, or a worker's failure that is not the test's own outcome, never
changes a calibration's answer: it is refused on one line naming it."""

import numpy as np
import pytest

import poro2d.calibration.cluster as cluster
from poro2d.calibration.case import shear_base_settings
from poro2d.calibration.cluster import UnitRunner
from poro2d.calibration.units import CalibrationUnit, UnitRow
from poro2d.errors import InputError
from poro2d.execute import Backend, Executor, RunOptions
from poro2d.store import Store

BASE = shear_base_settings({"max_displacement": 0.002})


def _unit(sigma: float = 50.0, specimen="s.npz") -> CalibrationUnit:
    return CalibrationUnit.at(specimen, "ab" * 32, sigma, BASE, 0.8, 0.15)


def test_an_intact_or_absent_entry_passes(tmp_path):
    cache = Store(tmp_path / "cache")
    unit = _unit()
    unit.check_entry(cache)  # absent: to be computed
    unit.store(cache).write_json("test.json", {"a": 1})
    unit.check_entry(cache)
    unit.check_entry(None)


def test_a_file_where_the_tests_folder_belongs_is_refused_naming_it(tmp_path):
    cache = Store(tmp_path / "cache")
    unit = _unit()
    (tmp_path / "cache").mkdir()
    (tmp_path / "cache" / unit.key).write_text("junk")
    with pytest.raises(InputError, match="a file") as exc:
        unit.check_entry(cache)
    assert unit.key in str(exc.value) and len(str(exc.value).splitlines()) == 1


def test_a_file_where_the_cache_belongs_is_refused_naming_it(tmp_path):
    (tmp_path / "cache").write_text("junk")
    with pytest.raises(InputError, match="a file") as exc:
        _unit().check_entry(Store(tmp_path / "cache"))
    assert str(tmp_path / "cache") in str(exc.value)


@pytest.mark.parametrize("damage", ["edit", "truncate"])
def test_a_changed_file_of_the_entry_is_refused_naming_it(tmp_path, damage):
    cache = Store(tmp_path / "cache")
    unit = _unit()
    store = unit.store(cache)
    store.write_json("result.json", {"peak_shear_stress_kpa": 38.7})
    store.write_arrays("consolidated.npz", x=np.arange(1000.0))
    if damage == "edit":
        path, text = store.path("result.json"), '{"peak_shear_stress_kpa": 99.0}'
        path.write_text(text)
    else:
        path = store.path("consolidated.npz")
        path.write_bytes(path.read_bytes()[:100])
    with pytest.raises(InputError, match="changed since it was written") as exc:
        unit.check_entry(cache)
    assert path.name in str(exc.value)


def _runner(monkeypatch, error: BaseException | None) -> UnitRunner:
    """A runner on the inline backend whose units fail with ``error`` (None: they give a row)."""

    def compute(unit, cache):
        if error is not None:
            raise error
        return UnitRow(unit.key, unit.sigma, unit.fp, unit.mu_r, unit.specimen, 40.0, 30.0, 1.0)

    monkeypatch.setattr(cluster, "compute_unit", compute)
    runner = UnitRunner(RunOptions(workers=1, dashboard=None, progress=False))
    runner.executor = Executor(Backend("inline"))
    return runner


def test_a_worker_failure_that_is_not_the_tests_outcome_stops_the_calibration(
    specimen, tmp_path, monkeypatch
):
    runner = _runner(monkeypatch, FileExistsError(17, "File exists"))
    units = [_unit(50.0, specimen), _unit(100.0, specimen)]
    with pytest.raises(RuntimeError, match="failed on a worker") as exc:
        runner.run(units, Store(tmp_path / "cache"), "round 1")
    assert "no answer is computed without it" in str(exc.value) and "(and 1 more)" in str(exc.value)


def test_a_test_without_equilibrium_is_left_out_and_said(specimen, tmp_path, monkeypatch):
    runner = _runner(monkeypatch, RuntimeError("consolidation at 50 kPa did not reach equilibrium"))
    rows = runner.run([_unit(50.0, specimen)], Store(tmp_path / "cache"), "round 1")
    assert rows == [None] and len(runner.failures) == 1 and "equilibrium" in runner.failures[0].error


def test_units_that_run_give_their_rows(specimen, tmp_path, monkeypatch):
    runner = _runner(monkeypatch, None)
    rows = runner.run([_unit(50.0, specimen)], Store(tmp_path / "cache"), "round 1")
    assert [r.key for r in rows] == [_unit(50.0, specimen).key] and runner.failures == []
