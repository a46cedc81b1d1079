"""Figures fit for print and the paper report as a user reads it.

Every figure is a 300 dpi PNG with an SVG beside it, its text written with mathematical symbols
(no ``tau_peak``, ``+-``, ``sigma_`` or ``phi_`` typed as text), its colours from the Okabe-Ito
palette; the replicate Fig. 8 has its dilation panel; the porosity profile is scaled to the packing.
The report states the paper-mode caveat first, the quasi-static checks the shear tests recorded and
K0 beside Jaky's. Inputs are the stored result files of ``tests/data/before_typed_results`` and
small arrays, so that no DEM run is needed.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from poro2d.criterion.result import CriterionOutputs, CriterionResult
from poro2d.measure.specimen_state import SpecimenStateResult
from poro2d.paper import PaperSummary
from poro2d.report.document import to_markdown
from poro2d.report.figure_file import DPI, PALETTE, figure_files, new_figure, save_figure
from poro2d.report.paper_report import PAPER_MODE_CAVEAT, build_blocks, jaky_k0
from poro2d.report.shear_figures import (
    curve_band,
    plot_peak_strength,
    plot_replicate_curves,
    plot_shear_curves,
)
from poro2d.report.specimen_figures import plot_specimen_state, porosity_axis
from poro2d.shear.fit import mohr_coulomb
from tests.report.print_checks import check_print_ready, typed_text

STORED = Path(__file__).parents[1] / "data" / "before_typed_results"


def test_dpi_and_palette_are_chosen_once():
    assert DPI == 300
    # Okabe and Ito's eight colours (Wong 2011), each once
    assert {c.upper() for c in PALETTE} == {
        "#000000", "#E69F00", "#56B4E9", "#009E73", "#F0E442", "#0072B2", "#D55E00", "#CC79A7",
    }  # fmt: skip
    fig, ax = new_figure()
    lines = [ax.plot([0, 1], [k, k])[0] for k in range(3)]
    assert [ln.get_color() for ln in lines] == list(PALETTE[:3])  # series take the palette in turn


def test_every_saved_figure_has_its_svg_beside_it(tmp_path):
    assert figure_files(tmp_path / "a.png") == [tmp_path / "a.png", tmp_path / "a.svg"]
    # a caller naming the SVG itself gets it once
    assert figure_files(tmp_path / "a.png", tmp_path / "a.svg") == [tmp_path / "a.png", tmp_path / "a.svg"]
    fig, ax = new_figure()
    ax.set_xlabel(r"$\tau_{peak}$ (kPa)")
    save_figure(fig, tmp_path / "a.png")
    assert check_print_ready(tmp_path / "a.png")


def test_the_checker_catches_symbols_typed_as_text(tmp_path):
    fig, ax = new_figure()
    ax.set_title("tau_peak = 3 +- 1")
    save_figure(fig, tmp_path / "bad.png")
    with pytest.raises(AssertionError):
        check_print_ready(tmp_path / "bad.png")
    assert typed_text(r"$\sigma'_n$ = 50 kPa, $\pm$ sd") == "  = 50 kPa,   sd"


def _curves(plate_rise: float) -> dict[float, dict[str, np.ndarray]]:
    """Two normal stresses' curves: tau rising to a plateau, the plate rising linearly."""
    x = np.linspace(0.0, 4.0, 41)
    return {
        s: {
            "shear_displacement_mm": x,
            "shear_stress_kpa": 0.7 * s * (1.0 - np.exp(-2.0 * x)),
            "plate_displacement_mm": plate_rise * x * 50.0 / s,
        }
        for s in (50.0, 100.0)
    }


def test_curve_band_of_the_plate_is_the_mean_and_sd_of_the_specimens():
    a, b = _curves(0.1)[50.0], _curves(0.3)[50.0]  # two specimens at one stress: plate 0.1 x and 0.3 x
    band = curve_band([a, b], points=5)
    x = band.shear_displacement_mm
    assert x[-1] == pytest.approx(4.0)
    assert band.plate_mean_mm == pytest.approx(0.2 * x)
    assert band.plate_sd_mm == pytest.approx(math.sqrt(2.0) * 0.1 * x)  # sd of {0.1 x, 0.3 x}, ddof 1
    no_plate = {k: v for k, v in a.items() if k != "plate_displacement_mm"}
    assert curve_band([no_plate, b]).plate_mean_mm is None


def test_fig8_over_specimens_has_its_dilation_panel(tmp_path):
    per_specimen = [_curves(0.1), _curves(0.2), _curves(0.3)]
    bands = {s: curve_band([c[s] for c in per_specimen]) for s in (50.0, 100.0)}
    png = plot_replicate_curves(bands, tmp_path / "fig8a.png", 3)
    texts = check_print_ready(png)
    assert any("dilation" in t for t in texts)  # the panel's label
    assert any(r"$\sigma'_n$ = 50 kPa" in t for t in texts)
    # without the plate's curve there is no panel
    flat = {s: curve_band([{k: v for k, v in c[s].items() if k != "plate_displacement_mm"}
                           for c in per_specimen]) for s in (50.0, 100.0)}  # fmt: skip
    assert not any(
        "dilation" in t for t in check_print_ready(plot_replicate_curves(flat, tmp_path / "f.png", 3))
    )


def test_shear_figures_are_print_ready(tmp_path):
    curves = _curves(0.2)
    check_print_ready(
        plot_shear_curves(curves, tmp_path / "a.png", peaks={50.0: (0.002, 30.0)}, smoothing_note="n")
    )
    sig, tau = np.array([50.0, 100.0, 200.0]), np.array([40.0, 75.0, 150.0])
    fit, origin = mohr_coulomb(sig, tau), mohr_coulomb(sig, tau, through_origin=True)
    texts = check_print_ready(plot_peak_strength(sig, tau, fit, tmp_path / "b.png", fit_origin=origin))
    assert any(r"$\varphi$" in t for t in texts) and any(r"$R^2$" in t for t in texts)


def _stored_state() -> SpecimenStateResult:
    """The accepted specimen's state a paper run stored: its top band holds the gap under the plate."""
    return SpecimenStateResult.from_dict(json.loads((STORED / "specimen_state.json").read_text()))


def test_porosity_profile_is_scaled_to_the_packing(tmp_path):
    state = _stored_state()
    n = [b.porosity for b in state.bands]
    assert n[-1] > 0.5 > max(n[:-1])  # the top band with the gap is far beyond the rest
    lo, hi = porosity_axis(n)
    assert lo < min(n[:-1]) and max(n[:-1]) < hi < 0.3  # the packing fills the axis, not the gap
    assert porosity_axis([0.15, 0.16, 0.17]) == pytest.approx((0.14, 0.18))  # margin at least 0.01
    texts = check_print_ready(plot_specimen_state(state, tmp_path / "state.png"))
    # the top band's value at the axis' edge, said to be the gap's (a line of text each)
    assert f"{n[-1]:.3f}" in texts and "(gap under" in texts
    assert any(r"$K_0 = \sigma_h / \sigma_v$" in t for t in texts)


def _report() -> tuple[str, PaperSummary, SpecimenStateResult]:
    summary = PaperSummary.from_dict(json.loads((STORED / "paper_results.json").read_text()))
    crit = CriterionResult.from_dict(json.loads((STORED / "criterion_result.json").read_text()))
    state = _stored_state()
    md = to_markdown(build_blocks(Path("."), summary, CriterionOutputs(crit, state)), Path("."))
    return md, summary, state


def test_report_says_what_paper_mode_is_first():
    md, _, _ = _report()
    first_note = next(line for line in md.splitlines() if line.startswith("> "))
    assert first_note == "> " + PAPER_MODE_CAVEAT
    assert md.index(PAPER_MODE_CAVEAT) < md.index("## Summary")
    assert "ignores" in PAPER_MODE_CAVEAT and "Eq. 12" in PAPER_MODE_CAVEAT
    assert "`poro2d sand`" in PAPER_MODE_CAVEAT


def test_report_shows_the_quasi_static_checks_it_promises():
    md, summary, _ = _report()
    assert "### Quasi-static checks" in md
    tests = summary.shear.tests
    rows = [line for line in md.splitlines() if line.startswith("| ") and "inertial" not in line]
    for t in tests:
        # each test's largest inertial number, its force balance and its coordination at the end
        row = next(
            r for r in rows if r.startswith(f"| {t.normal_stress_kpa:g} | {t.max_inertial_number:.2e}")
        )
        assert f"{100 * t.force_balance.mean_abs_upper_minus_plane_rel:.1f} %" in row
        assert f"{t.end.coordination_number:.2f}" in row
    assert f"limit {summary.shear.quasi_static.inertial_limit:g}" in md


def test_report_compares_k0_with_jaky_for_the_measured_angle():
    md, summary, state = _report()
    phi = summary.shear.friction_angle_deg
    jaky = 1.0 - math.sin(math.radians(phi))  # Jaky (1944), independently of the report's function
    assert jaky_k0(30.0) == pytest.approx(0.5)
    assert f"| {state.k0_mean:.2f} (sd" in md
    assert f"phi = {phi:.1f} deg (this run's direct shear peaks) | {jaky:.2f} |" in md
    assert f"| ratio of the two | {state.k0_mean / jaky:.2f} |" in md
    assert f"is not Jaky's 1 - sin phi ({jaky:.2f} for the angle this run measured)" in md


def test_force_legend_writes_numbers_as_a_reader_does():
    from poro2d.report.force_chains import force_text

    assert [force_text(v) for v in (1e4, 2500.0, 500.0, 2.5)] == ["10,000", "2,500", "500", "2.5"]
    assert force_text(3.854e6) == r"$3.85 \times 10^{6}$" and force_text(2e-5) == r"$2 \times 10^{-5}$"


def test_k0_note_says_agreement_only_when_k0_is_near_jakys():
    from poro2d.report.paper_report import k0_blocks, k0_note

    assert "is within 15% of Jaky's" in k0_note(0.42, jaky_k0(36.0))  # 0.42 against 0.41
    assert "is not Jaky's 1 - sin phi (0.41" in k0_note(0.90, jaky_k0(36.0))
    assert "about 0.4-0.5 for sands" in k0_note(0.90)  # no angle measured: the sands' range
    table = k0_blocks(0.9, None, None)[0]
    assert len(table[2]) == 1  # without an angle, only the specimen's K0
