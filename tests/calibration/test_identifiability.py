"""A calibration whose design cannot estimate its own noise never answers as if identified.

Too few design points, twin specimens and replicates of other boxes or gradings are refused
on one line before any test; one specimen runs, its intervals reported as unknown; a
posterior that is not finite is no answer at all.
"""

import shutil
from pathlib import Path

import numpy as np
import pytest

from poro2d.calibration import CalibrationCase, model, run_calibration
from poro2d.calibration.case import MIN_POINTS, shear_base_settings
from poro2d.calibration.run import _infer, _units, unidentified_reason
from poro2d.calibration.specimens import check_replicates, replicate_unit
from poro2d.calibration.units import CalibrationUnit, UnitRow
from poro2d.cli.calibrate import print_result
from poro2d.dem import checkpoint
from poro2d.errors import InputError
from poro2d.execute.options import RunOptions
from poro2d.report.calibration_figures import draw_calibration
from poro2d.specimen.specimen_set import SpecimenSet
from poro2d.store import Store

QUIET = RunOptions(progress=False)
ONE_WORKER = RunOptions(workers=1, dashboard=None, progress=False)

SHORT = {"max_displacement": 0.002, "peak_window": 5e-4, "checkpoint_interval": 5e-4, "record_interval": 5e-5}
LAB = "normal_stress_kpa,peak_shear_stress_kpa\n50,40\n100,75\n"


@pytest.fixture
def lab(tmp_path):
    path = tmp_path / "lab.csv"
    path.write_text(LAB)
    return path


def test_the_design_keeps_degrees_of_freedom_for_the_surrogates_residual():
    assert MIN_POINTS == model.N_COEFFICIENTS + 3


@pytest.mark.parametrize("points", [6, MIN_POINTS - 1])
def test_a_design_that_fits_the_surrogate_exactly_is_refused_before_any_test(specimen, lab, tmp_path, points):
    other = tmp_path / "other.npz"
    shutil.copyfile(specimen, other)
    out = tmp_path / "out"
    with pytest.raises(InputError, match="--points"):
        run_calibration(
            CalibrationCase.of(lab, [specimen, other], points=points, settings=SHORT),
            Store(out),
            options=QUIET,
        )
    assert not (out / "cache").exists()


def test_twin_specimens_are_refused_naming_the_twin(specimen, lab, tmp_path):
    twin = tmp_path / "twin.npz"
    shutil.copyfile(specimen, twin)  # another file, the same content
    out = tmp_path / "out"
    with pytest.raises(InputError, match="twin") as exc:
        run_calibration(CalibrationCase.of(lab, [specimen, twin], settings=SHORT), Store(out), options=QUIET)
    assert "twin.npz" in str(exc.value) and len(str(exc.value).splitlines()) == 1
    assert not (out / "cache").exists()


def test_replicates_of_another_grading_are_refused(specimen, lab, tmp_path):
    sim = checkpoint.load(specimen)
    sim.particles.radius[:] *= 1.5  # the same box, disks of another grading
    coarse = tmp_path / "coarse.npz"
    checkpoint.save(sim, coarse)
    out = tmp_path / "out"
    with pytest.raises(InputError, match="another grading") as exc:
        run_calibration(
            CalibrationCase.of(lab, [specimen, coarse], settings=SHORT), Store(out), options=QUIET
        )
    assert "coarse.npz" in str(exc.value)
    assert not (out / "cache").exists()


def test_replicates_of_another_box_are_refused(specimen, tmp_path):
    sim = checkpoint.load(specimen)
    walls = sim.walls
    right = list(walls.names).index("right")
    walls.p0[right, 0] += 0.01
    walls.p1[right, 0] += 0.01
    wider = tmp_path / "wider.npz"
    checkpoint.save(sim, wider)
    with pytest.raises(InputError, match="wide"):
        check_replicates(SpecimenSet.accepted({"a": specimen, "b": wider}))


def test_zero_width_intervals_are_unknown_and_wide_ones_are_not():
    zero = {"particle_friction": [0.754, 0.754], "rolling_friction": [0.1, 0.2]}
    assert "zero width" in unidentified_reason(2, zero)
    assert "one specimen" in unidentified_reason(1, {"particle_friction": [0.3, 3.0]})
    assert unidentified_reason(2, {"particle_friction": [0.5, 0.9], "rolling_friction": [0.1, 0.2]}) is None


def test_a_posterior_that_is_not_finite_is_no_answer():
    ranges = model.Ranges((0.3, 3.0), (0.0, 0.5))
    design = model.space_filling(ranges, MIN_POINTS, 0)
    base = shear_base_settings({"max_displacement": 0.002})
    found, digests = {"a": "a.npz", "b": "b.npz"}, {"a": "a" * 64, "b": "b" * 64}
    rows = []  # in the units' order: per design point, per specimen, per stress
    for k, (fp, mu_r) in enumerate(design):
        for label in found:
            unit = CalibrationUnit.at(found[label], digests[label], 50.0, base, fp, mu_r)
            peak = 30.0 + 10.0 * fp + k + (label == "b")
            rows.append(UnitRow(unit.key, 50.0, fp, mu_r, found[label], peak, peak, 1.0))
    targets = [("peak", 50.0, 1e300)]  # an absurd laboratory value: the misfit overflows
    with pytest.raises(RuntimeError, match="posterior"):
        known = SpecimenSet(("a", "b"), (Path("a.npz"), Path("b.npz")), ("a" * 64, "b" * 64))
        _infer(ranges, design, known, [50.0], rows, targets, 0.0)


def test_the_table_reads_each_units_row_in_the_units_order():
    """Rows come back in the units' order: each design point's replicate values are its own
    specimens' at its own stress, whatever the number of specimens and stresses."""
    ranges = model.Ranges((0.3, 3.0), (0.0, 0.5))
    design = model.space_filling(ranges, MIN_POINTS, 0)
    base = shear_base_settings({"max_displacement": 0.002})
    found = SpecimenSet(tuple("abc"), tuple(Path(f"{k}.npz") for k in "abc"), tuple(k * 64 for k in "abc"))
    stresses = [50.0, 100.0]
    units = _units(design, found, stresses, base)

    def peak(unit):  # linear in the stress, with a seed scatter: a posterior that can be computed
        return (
            unit.sigma * (0.4 + 0.2 * unit.fp)
            + 2.0 * unit.mu_r
            + {"a.npz": 0.0, "b.npz": 1.0, "c.npz": -1.0}[unit.specimen]
        )

    rows = [UnitRow(u.key, u.sigma, u.fp, u.mu_r, u.specimen, peak(u), 0.9 * peak(u), 1.0) for u in units]
    rows[4] = None  # a failed test: NaN in its place only
    by_key = {u.key: r for u, r in zip(units, rows, strict=True)}
    targets = [("peak", 50.0, 40.0), ("peak", 100.0, 75.0)]
    _, _, table = _infer(ranges, design, found, stresses, rows, targets, 0.0)
    for (fp, mu_r), entry in zip(design, table, strict=True):
        for s in stresses:
            expected = []
            for label in found:
                row = by_key[replicate_unit(found, label, s, base, fp, mu_r).key]
                expected.append(row.peak if row is not None else None)
            (obs,) = [o for o in entry.observed if o.normal_stress_kpa == s]
            got = [None if v != v else v for v in obs.values]
            assert got == expected
    assert sum(v != v for e in table for o in e.observed for v in o.values) == 1
    # the file's row: the pair, then a key per target in the targets' order
    assert list(table[0].to_dict()) == ["particle_friction", "rolling_friction", "peak_50kPa", "peak_100kPa"]


def test_one_specimen_reports_its_intervals_as_unknown(specimen, lab, tmp_path, capsys):
    out = tmp_path / "out"
    res = run_calibration(
        CalibrationCase.of(
            lab, [specimen], points=MIN_POINTS, refine=0, settings=SHORT, keep_box_dominated=True
        ),
        Store(out),
        options=ONE_WORKER,
    )
    draw_calibration(res, Store(out))  # the figures and the report, as the command draws them
    assert "one specimen" in res.unidentified
    assert res.intervals.to_dict() == {"particle_friction": None, "rolling_friction": None}
    assert res.posterior.wide.to_dict() == {"particle_friction": None, "rolling_friction": None}
    kept = Store(out).read_json("result.json")
    assert kept["unidentified"] == res.unidentified and kept["intervals"]["particle_friction"] is None
    assert "Not identified" in (out / "calibration.md").read_text()
    assert "NOT IDENTIFIED" in (out / "calibrated.toml").read_text()
    print_result(res, out)
    printed = capsys.readouterr().out
    assert "interval unknown" in printed and "Not identified" in printed
    assert "narrower than half" not in printed
    # the box the frictions were fitted in: a few hundred disks is a box-scale box, said at the
    # command, in the report and in the file
    radii = np.load(specimen)["particles.radius"]
    assert res.box_scale.disks == radii.size and res.box_scale.d_max_m == 2 * radii.max()
    assert res.box_scale.box_scale and kept["box_scale"]["box_scale"] is True
    assert "fitted to a box-scale box" in printed
    assert "fitted to a box-scale box" in (out / "calibration.md").read_text()
