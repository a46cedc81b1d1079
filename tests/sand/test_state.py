"""A sand config's [state] table: the laboratory line, the test stress, the 2D line it must match."""

from __future__ import annotations

import pytest

from poro2d.critical_state import CriticalStateCase
from poro2d.critical_state.line import run_critical_state_line
from poro2d.critical_state.state_table import state_map_lines, state_map_record, state_request
from poro2d.errors import InputError
from poro2d.execute import RunOptions
from poro2d.grading import paper_grading
from poro2d.lab_state import lab_state_from_table
from poro2d.sand import load_sand_case
from poro2d.state_map import map_state, published_line
from poro2d.store import Store

LAB = lab_state_from_table({"e_max": 0.977, "e_min": 0.597, "dr": 0.8})
SMALL = {"disks": 200, "inertial_number": 1e-2, "strain": 0.6, "window_start": 0.3, "blocks": 3}


@pytest.fixture(scope="module")
def line_folder(tmp_path_factory):
    """A tiny 2D line of the paper grading at Table 1's working friction 3.0 (the specimens')."""
    folder = tmp_path_factory.mktemp("line")
    case = CriticalStateCase(**SMALL, particle_friction=3.0)
    run_critical_state_line(case, [50.0, 200.0], Store(folder), seeds=1, options=RunOptions(workers=1))
    return folder


def test_the_state_map_of_a_sand_config_is_map_state_at_its_stress(line_folder):
    req = state_request(
        {"lab_line": "toyoura", "test_stress_kpa": 100, "line_2d": str(line_folder)},
        LAB, None, 3.0, 0.0, paper_grading(),
    )  # fmt: skip
    assert req.test_stress_kpa == 100.0 and req.line_2d is not None
    rec = state_map_record(req, LAB, 0.22, 0.16, 0.17, "paper")
    line, _, _ = published_line("toyoura")
    m = map_state(LAB.e, 0.977, 0.597, line, 100.0, req.line_2d.void_ratio_at, 0.22 / 0.78, 0.16 / 0.84)
    assert rec.e2d_by_state == pytest.approx(m.e2d_by_state) and rec.psi_norm_lab == pytest.approx(m.psi_norm)
    assert rec.psi_norm_by_dr == pytest.approx((0.17 / 0.83 - m.e_cs_2d) / (0.22 / 0.78 - 0.16 / 0.84))
    assert rec.n2d_by_state == pytest.approx(m.e2d_by_state / (1.0 + m.e2d_by_state))
    text = " ".join(state_map_lines(rec))
    assert "relative-density map" in text and f"{rec.n2d_by_state:.4f}" in text


def test_a_2d_line_of_other_disks_is_refused(line_folder):
    table = {"lab_line": "toyoura", "line_2d": str(line_folder)}
    with pytest.raises(InputError) as exc:  # the specimens work at another friction
        state_request(table, LAB, None, 0.5, 0.0, paper_grading())
    assert "particle_friction" in exc.value.parameter and "--particle-friction 0.5" in exc.value.hint
    from poro2d.grading import preset_grading

    with pytest.raises(InputError) as exc:  # another grading
        state_request(table, LAB, None, 3.0, 0.0, preset_grading("wide_cu4"))
    assert "grading" in exc.value.parameter


@pytest.mark.parametrize(
    ("state", "parameter"),
    [
        ({"lab_line": "nowhere"}, "state.lab_line"),
        ({"test_stress_kpa": 100}, "state.lab_line"),
        ({"lab_line": "toyoura", "test_stress_kpa": -5}, "state.test_stress_kpa"),
        ({"lab_line": "toyoura", "depth": 3}, "state"),
        ({"lab_line": "toyoura", "line_2d": "no-such-folder"}, "state.line_2d"),
    ],
)
def test_a_bad_state_table_is_refused_before_any_work(state, parameter):
    cfg = {
        "soil": {"name": "s"},
        "grading": {"preset": "paper"},
        "lab": {"e_max": 0.977, "e_min": 0.597, "dr": 0.5},
    }
    with pytest.raises(InputError) as exc:
        load_sand_case({**cfg, "state": state})
    assert exc.value.parameter.startswith(parameter)
