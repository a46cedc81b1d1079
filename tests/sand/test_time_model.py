"""The pre-flight's time model, piece by piece, against values worked by hand."""

import pytest

from poro2d.sand import load_sand_case
from poro2d.sand import preflight as PF
from poro2d.specimen.compaction import SpecimenSpec

TOYOURA = {
    "soil": {"name": "test sand"},
    "grading": {"preset": "paper"},
    "lab": {"e_max": 0.977, "e_min": 0.597, "dr": 0.8},
}


def test_lid_steps_rise_with_the_preparation_friction_between_measured_points():
    assert PF.lid_steps(0.0) == 32_000 and PF.lid_steps(1.0) == 73_000
    # mu 0.55 lies halfway between (0.1, 37 000) and (1.0, 73 000): 37 000 + 0.5 x 36 000
    assert PF.lid_steps(0.55) == pytest.approx(55_000)
    assert PF.lid_steps(5.0) == 73_000  # flat beyond the most frictional point measured
    # a full-size specimen's lid finds its packing near, whatever the friction
    assert PF.lid_steps(0.0, "specimens") == PF.lid_steps(1.0, "specimens") == 6_000


def test_trials_per_case_are_the_measured_ones_by_stage():
    mus = (0.0, 0.05, 0.1, 1.0)
    assert PF.trials_per_case(0.0, mus, "calibration") == 1.0  # the dense end
    assert PF.trials_per_case(1.0, mus, "calibration") == 1.5  # the loose end
    assert PF.trials_per_case(0.1, mus, "calibration") == 1.5  # a friction around the state
    assert PF.trials_per_case(0.064, mus, "specimens") == 1.2


def test_a_trials_steps_are_its_layers_growth_and_settling_and_its_lid():
    spec = SpecimenSpec(width=0.1, height=0.05, layers=3, growth_increments=40, growth_steps=150)
    # 3 layers x (40 x 150 + 14 000 x 2) at half the paper grading's step
    assert PF.preparation_steps(spec, 2.0) == pytest.approx(3 * (6_000 + 28_000))
    # a wide grading's layers settle longer: 50 000 steps each
    assert PF.preparation_steps(spec, 2.0, wide=True) == pytest.approx(3 * (6_000 + 100_000))
    # 1.5 trials x (102 000 + 73 000 x 2)
    assert PF.case_steps(spec, 1.0, 1.5, 2.0) == pytest.approx(1.5 * (102_000 + 146_000))
    # a specimen's trial: 1.2 x (102 000 + 6 000 x 2)
    assert PF.case_steps(spec, 1.0, 1.2, 2.0, "specimens") == pytest.approx(1.2 * (102_000 + 12_000))


def test_cases_go_to_the_worker_that_frees_first_the_longest_first():
    # 5 -> w1, 4 -> w2, 3 -> w2 (7), 2 -> w1 (7): both end together, no core spare
    assert PF.wall_seconds([2.0, 5.0, 3.0, 4.0], 2) == 7.0
    assert PF.wall_seconds([3.0, 3.0, 3.0], 3) == 3.0


def test_a_case_alone_takes_the_spare_cores_as_threads():
    # 10 -> w1, the three 1 s cases on w2 until t = 3; then 7 s left on 2 threads (1.7x)
    assert PF.thread_gain(1) == 1.0 and PF.thread_gain(2) == pytest.approx(1.7)
    assert PF.wall_seconds([10.0, 1.0, 1.0, 1.0], 2) == pytest.approx(3.0 + 7.0 / 1.7)
    # two cases on 4 cores: 2 threads each from the start
    assert PF.wall_seconds([1.0, 1.0], 4) == pytest.approx(1.0 / 1.7)
    # 4 -> w1, 2 -> w2; at t = 2 the 2 s left of the first run on 2 threads
    assert PF.wall_seconds([4.0, 2.0], 2) == pytest.approx(2.0 + 2.0 / 1.7)


def test_the_state_chooses_the_frictions_around_it_before_any_run():
    # Dr 0.8: a share 0.2 between the ends, n2D 0.163 + 0.2 x 0.059 = 0.1748 on the shape,
    # between (0.05, 0.171) and (0.1, 0.176): mu = 0.05 + 0.05 x 0.0038 / 0.005 = 0.088
    assert PF.friction_at_share(0.2, (0.0, 1.0)) == pytest.approx(0.088, abs=1e-9)
    case = load_sand_case(TOYOURA)
    ends, inner, specimens = PF.case_plans(case)
    assert ends.frictions == (1.0, 0.0) and inner.frictions == (0.05, 0.1)
    assert specimens.frictions[0] == pytest.approx(PF.expected_friction(case))
    assert (ends.count, inner.count, specimens.count) == (4, 4, 3)


def test_the_estimate_scales_with_the_throughput_given(tmp_path, monkeypatch):
    monkeypatch.setenv("PORO2D_CACHE", str(tmp_path))
    monkeypatch.setattr(PF, "JAMMING_DISKS", 200)
    case = load_sand_case(TOYOURA)
    fast = PF.preflight(case, workers=2, throughput=2e7)
    slow = PF.preflight(case, workers=2, throughput=1e7)
    assert slow.seconds.total == pytest.approx(2.0 * fast.seconds.total)
    assert fast.particle_steps.calibration == slow.particle_steps.calibration
    assert fast.throughput == 2e7
