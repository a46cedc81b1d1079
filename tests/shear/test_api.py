"""The direct shear package's Python API: ``run_shear`` and the peak's force-chain frame.
A small specimen (0.06 m x 0.03 m) and 2 mm of shear, as in tests/shear/test_shear.py: every test
runs in seconds."""

import json

import numpy as np
import pytest

from poro2d.dem import checkpoint
from poro2d.errors import InputError
from poro2d.execute import RunOptions
from poro2d.report.force_chains import plot_force_chains
from poro2d.report.shear_figures import draw_shear_series
from poro2d.shear import ShearSeries, ShearSeriesCase, ShearSettings, build_split_box, run_shear
from poro2d.shear.curve import CURVE_COLUMNS, ShearRow
from poro2d.shear.lab import read_lab_csv
from poro2d.shear.peak_frame import PeakFrame, PeakTracker
from poro2d.store import Store

#: the tests one after the other in this process, no bars
SERIAL = RunOptions(workers=1, progress=False)

SHORT = {"max_displacement": 0.002, "peak_window": 5e-4, "checkpoint_interval": 5e-4}
# the keys of peak_frame.npz as earlier versions of poro2d wrote them: a test they left
# unfinished resumes with its peak frame
FRAME_KEYS = {"pos", "radius", "thickness", "wall_p0", "wall_p1", "record", "displacement_mm"} | {
    "c_" + k for k in ("i", "j", "kind", "point", "normal", "fn", "fs", "force", "branch")
}


def test_run_shear_is_the_series_with_its_files(specimen, tmp_path):
    lab = tmp_path / "lab.csv"
    lab.write_text("normal_stress_kpa,peak_shear_stress_kpa\n50,40\n100,75\n")
    out = tmp_path / "api"
    res = run_shear(
        ShearSeriesCase(specimen.parent, [50, 100], SHORT, lab=lab, config={"note": "kept"}),
        Store(out),
        options=SERIAL,
    )
    assert res.to_dict() == json.loads((out / "result.json").read_text())
    assert res.config == {"note": "kept"} and res.settings.max_displacement == 0.002
    assert res.lab.friction_angle_deg == pytest.approx(np.degrees(np.arctan(35 / 50)))
    assert (out / "sn50kPa" / "peak_frame.npz").is_file()  # the peak's state, kept for its figure
    assert not (out / "sn50kPa" / "forces_peak.png").exists()  # no figure during a run
    draw_shear_series(res, Store(out), read_lab_csv(lab))
    for f in ("curves.csv", "peaks.csv", "fig8a_shear_curves.png", "fig8b_peak_strength.png",
              "sn50kPa/forces_peak.png", "sn100kPa/curve.csv"):  # fmt: skip
        assert (out / f).stat().st_size > 0, f
    assert not (out / "sn50kPa" / "peak_frame.npz").exists()  # removed once drawn
    ref = ShearSeries(specimen, [50, 100], ShearSettings(**SHORT), store=Store(tmp_path / "series"),
                      options=SERIAL, keep_peak=False).run()  # fmt: skip
    assert [t.peak_shear_stress_kpa for t in res.tests] == [t.peak_shear_stress_kpa for t in ref.tests]
    again = run_shear(
        ShearSeriesCase(specimen, 100, ShearSettings(**SHORT)), Store(out / "one"), options=SERIAL
    )
    assert again.tests[0].peak_shear_stress_kpa == ref.tests[1].peak_shear_stress_kpa


@pytest.mark.parametrize(
    ("kw", "name"),
    [
        ({"normal_stresses_kpa": "50,100"}, "normal_stresses_kpa"),
        ({"normal_stresses_kpa": [50, -1]}, "normal stress"),
        ({"normal_stresses_kpa": []}, "normal stress"),
        ({"settings": {"velocty": 0.01}}, "settings.velocty"),
        ({"settings": {"velocity": "0.01"}}, "settings.velocity"),
        ({"settings": 0.01}, "settings"),
        ({"settings": {"max_displacement": 0.05}}, "max_displacement"),
        ({"lab": 5}, "lab"),
        ({"lab": "missing.csv"}, "lab"),
        ({"rate_check": "yes"}, "rate_check"),
        ({"specimen": "nowhere.npz"}, "specimen"),
    ],
)
def test_run_shear_refuses_bad_input_before_any_test(specimen, tmp_path, kw, name):
    args = {"specimen": specimen, "normal_stresses_kpa": [50], "settings": SHORT} | kw
    out = tmp_path / "out"
    with pytest.raises(InputError, match=name):
        run_shear(ShearSeriesCase(**args), Store(out), options=SERIAL)
    assert not out.exists()


def test_run_shear_refuses_a_file_as_out_and_a_damaged_specimen(specimen, tmp_path):
    taken = tmp_path / "taken"
    taken.write_text("x")
    with pytest.raises(InputError, match="out"):
        run_shear(ShearSeriesCase(specimen, [50]), Store(taken))
    with pytest.raises(InputError, match="store"):
        run_shear(ShearSeriesCase(specimen, [50]), taken)  # a path is not a store
    bad = tmp_path / "bad.npz"
    bad.write_bytes(specimen.read_bytes()[:100])
    with pytest.raises(InputError, match="checkpoint"):
        run_shear(ShearSeriesCase(bad, [50]), Store(tmp_path / "o"))
    assert not (tmp_path / "o").exists()


def test_peak_frame_round_trip_and_figure(specimen, tmp_path):
    sim, box = build_split_box(checkpoint.load(specimen), 0.002)
    sim.run(20)
    frame = PeakFrame.capture(sim, sim.contacts(), record=7, displacement_mm=0.35)
    frame.save(Store(tmp_path), "peak_frame.npz")
    with np.load(tmp_path / "peak_frame.npz") as z:
        assert set(z.files) == FRAME_KEYS
    back = PeakFrame.load(Store(tmp_path), "peak_frame.npz")
    assert back.record == 7 and back.displacement_mm == 0.35 and back.thickness == sim.particles.thickness
    np.testing.assert_array_equal(back.pos, sim.particles.pos)
    np.testing.assert_array_equal(back.walls[:, 1], sim.walls.p1)
    np.testing.assert_array_equal(back.contacts.fn, frame.contacts.fn)
    sim.particles.pos[0, 0] += 1.0  # the frame is a copy, not a view of the running state
    assert back.pos[0, 0] != sim.particles.pos[0, 0] and frame.pos[0, 0] != sim.particles.pos[0, 0]
    b = box
    png = plot_force_chains(
        back.contacts,
        back.pos,
        back.radius,
        back.walls,
        tmp_path / "forces.png",
        thickness=back.thickness,
        title="peak",
        box=(0.0, 0.0, b.width + 0.002, b.height),
    )
    assert png.stat().st_size > 0


def _frame(k: int) -> PeakFrame:
    empty = np.zeros((0, 2))
    from poro2d.dem.contacts import ContactSet

    c = ContactSet(np.zeros(0, int), np.zeros(0, int), np.zeros(0, int), empty, empty, np.zeros(0),
                   np.zeros(0), empty, empty)  # fmt: skip
    return PeakFrame(np.zeros((1, 2)), np.ones(1), 0.01, np.zeros((0, 2, 2)), c, k, float(k))


def test_peak_tracker_keeps_the_frame_of_the_smoothed_maximum(tmp_path):
    # a lone spike at record 2 and a broad hump around record 8: the smoothed peak is the hump
    tau = [0.0, 1.0, 9.0, 1.0, 0.0, 0.0, 4.0, 5.0, 6.0, 5.0, 4.0, 0.0, 0.0]
    zeros = dict.fromkeys(CURVE_COLUMNS, 0.0)
    rows = [ShearRow(**dict(zeros, shear_displacement_mm=k, shear_stress_kpa=t)) for k, t in enumerate(tau)]
    tracker = PeakTracker(window=4e-3)  # five records wide
    for k in range(len(rows)):
        tracker.add(_frame(k))
        tracker.settle(rows[: k + 1], 1e-3 * k)
        # a frame is final only once the records half a window past it exist (and then it is)
        waiting = {f.record for f in tracker.pending}
        assert set(range(max(0, k - 1), k + 1)) <= waiting and min(waiting) >= k - 2
    tracker.settle(rows, None)
    assert tracker.frame.record == 8 and tracker.value == pytest.approx(np.mean(tau[6:11]))
    tracker.save(Store(tmp_path), "f.npz")
    resumed = PeakTracker(window=4e-3)
    resumed.restore(Store(tmp_path), "f.npz", rows)
    assert resumed.frame.record == 8 and resumed.value == pytest.approx(tracker.value)
    resumed.save(Store(tmp_path), "g.npz")  # nothing new since the restore: nothing written
    assert not (tmp_path / "g.npz").exists()
