"""The laboratory critical-state line, Bolton's dilatancy and the two maps of a state into 2D."""

from __future__ import annotations

import math

import pytest

from poro2d.errors import InputError
from poro2d.state_map import (
    LabCriticalStateLine,
    bolton_dilatancy,
    line_of_table,
    map_state,
    published_line,
)


def test_the_power_and_semi_log_lines_read_as_written():
    power = LabCriticalStateLine(e_gamma=0.934, lam=0.019, xi=0.7, p_ref_kpa=101.0)
    assert power.void_ratio_at(101.0) == pytest.approx(0.934 - 0.019)
    assert power.void_ratio_at(400.0) == pytest.approx(0.934 - 0.019 * (400.0 / 101.0) ** 0.7)
    semi = LabCriticalStateLine(e_gamma=1.0, lam=0.05)
    assert semi.void_ratio_at(100.0) == pytest.approx(1.0 - 0.05 * math.log(100.0))


def test_toyoura_sand_is_at_its_critical_state_near_dr_015_at_100_kpa():
    """Verdugo & Ishihara's Toyoura line (Li & Wang's fit): e_cs(100 kPa) = 0.915, Dr 0.16 on
    e_max 0.977 and e_min 0.597; looser contracts, denser dilates."""
    line, e_max, e_min = published_line("Toyoura")
    e_cs = line.void_ratio_at(100.0)
    assert e_cs == pytest.approx(0.9151, abs=1e-4)
    assert (e_max - e_cs) / (e_max - e_min) == pytest.approx(0.163, abs=0.002)
    with pytest.raises(InputError):
        published_line("no such sand")


def test_a_table_is_read_linearly_in_ln_p_and_never_extrapolated():
    line = line_of_table([(400.0, 0.88), (50.0, 0.92)], source="hand")
    assert line.points[0] == (50.0, 0.92)
    mid = math.sqrt(50.0 * 400.0)
    assert line.void_ratio_at(mid) == pytest.approx(0.90)
    with pytest.raises(InputError):
        line.void_ratio_at(800.0)
    with pytest.raises(InputError):
        line_of_table([(100.0, 0.9)])
    with pytest.raises(InputError):
        line_of_table([(100.0, 0.9), (100.0, 0.8)])


def test_bolton_peak_above_critical_is_five_i_r_in_plane_strain():
    d = bolton_dilatancy(0.8, 100.0)
    assert d.relative_dilatancy_index == pytest.approx(0.8 * (10.0 - math.log(100.0)) - 1.0)
    assert d.plane_strain_deg == pytest.approx(5.0 * d.relative_dilatancy_index)
    assert d.triaxial_deg == pytest.approx(3.0 * d.relative_dilatancy_index)
    assert bolton_dilatancy(0.1, 100.0).relative_dilatancy_index == 0.0  # loose: no dilatancy
    assert bolton_dilatancy(1.0, 1.0).relative_dilatancy_index == 4.0  # capped


def test_the_maps_agree_where_the_2d_line_sits_where_the_lab_line_does():
    """If the 2D critical state lies at the same relative place between the 2D ends as the
    laboratory's between e_max and e_min, both maps give the same 2D void ratio."""
    line = LabCriticalStateLine(e_gamma=0.80, lam=0.0)  # e_cs 0.80 at every p': Dr_cs 0.5
    for dr in (0.0, 0.3, 1.0):
        e = 1.0 - dr * 0.4
        m = map_state(e, 1.0, 0.6, line, 100.0, lambda p: 0.25, 0.30, 0.20)
        assert m.e2d_by_state == pytest.approx(m.e2d_by_dr)
        assert m.psi2d_by_dr == pytest.approx(m.psi_norm)
    m = map_state(0.9, 1.0, 0.6, line, 100.0, lambda p: 0.28, 0.30, 0.20)
    assert m.psi_lab == pytest.approx(0.1) and m.psi_norm == pytest.approx(0.25)
    assert m.e2d_by_state == pytest.approx(0.28 + 0.25 * 0.1) and not m.state_within_ends


def test_a_state_outside_its_extremes_is_refused():
    line = LabCriticalStateLine(e_gamma=0.80, lam=0.0)
    with pytest.raises(InputError) as exc:
        map_state(1.1, 1.0, 0.6, line, 100.0, lambda p: 0.25, 0.30, 0.20)
    assert exc.value.parameter == "e"
    with pytest.raises(InputError):
        LabCriticalStateLine(e_gamma=0.8, lam=-0.1)
