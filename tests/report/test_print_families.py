"""Every family of figure besides the paper's is print-ready too: the biaxial curves and Mohr
circles, the periodic cell's stress ratio, the strength study, the relation and the sensitivity
study, each drawn from a stored result file or small arrays and checked as a 300 dpi PNG with its
SVG, no symbol typed as text."""

from __future__ import annotations

import json
from pathlib import Path
from types import SimpleNamespace

import numpy as np

from poro2d.report.biaxial_figures import plot_biaxial, plot_biaxial_series
from poro2d.report.critical_state_figures import plot_critical_state
from poro2d.report.relation_figure import write_relation_figure
from poro2d.report.sensitivity_report import plot_sensitivity
from poro2d.report.strength_figure import plot_strength
from poro2d.sweep.results import RelationResult
from tests.report.print_checks import check_print_ready

STORED = Path(__file__).parents[1] / "data" / "before_typed_results"


def _biaxial_curve(scale: float) -> dict[str, np.ndarray]:
    e1 = np.linspace(0.0, 0.1, 30)
    return {"axial_strain": e1, "sin_phi": scale * (1 - np.exp(-60 * e1)), "volumetric_strain": -0.2 * e1}


def test_biaxial_figures_are_print_ready(tmp_path):
    curves = [("replicate 1", _biaxial_curve(0.5)), ("replicate 2", _biaxial_curve(0.55))]
    texts = check_print_ready(plot_biaxial(curves, tmp_path / "b.png", title=r"$\sigma_3$ = 100 kPa",
                                           critical=(0.5, 0.05)))  # fmt: skip
    assert any(r"\sin\varphi" in t for t in texts) and any(r"\varepsilon_1" in t for t in texts)
    series = [(50.0, [_biaxial_curve(0.5)]), (100.0, [_biaxial_curve(0.5)])]
    peaks = [(50.0, 50.0, 0.5), (100.0, 100.0, 0.5)]
    texts = check_print_ready(plot_biaxial_series(series, tmp_path / "s.png", title="series",
                                                  envelope=(30.0, 1.0), peaks=peaks))  # fmt: skip
    assert any(r"$\varphi$ = 30.0°" in t for t in texts)


def test_critical_state_and_strength_figures_are_print_ready(tmp_path):
    gamma = np.linspace(0.0, 2.0, 50)
    s = SimpleNamespace(gamma=gamma, stress_ratio=0.3 + 0 * gamma, solid_fraction=0.8 + 0 * gamma)
    check_print_ready(plot_critical_state([("seed 0", s)], tmp_path / "c.png", title=r"$f_p$ = 0.5",
                                          window=1.0, steady=(0.3, 0.8)))  # fmt: skip
    rows = [SimpleNamespace(particle_friction=0.5, mu_r=mu, specimens=3,
                            peak_friction_angle_mean_deg=30 + 10 * mu, peak_friction_angle_sd_deg=1.0,
                            residual_friction_angle_mean_deg=25 + 5 * mu, residual_friction_angle_sd_deg=1.0,
                            max_dilation_angle_mean_deg=5 + mu, max_dilation_angle_sd_deg=0.5)
            for mu in (0.0, 0.1, 0.2)]  # fmt: skip
    check_print_ready(plot_strength(rows, tmp_path / "strength.png"))


def test_relation_and_sensitivity_figures_are_print_ready(tmp_path):
    rel = RelationResult.from_dict(json.loads((STORED / "relation_density_mode.json").read_text()))
    png, svg = write_relation_figure(rel, tmp_path, "relation")
    check_print_ready(png)
    sens = json.loads((STORED / "sensitivity.json").read_text())
    png, svg = plot_sensitivity(sens, tmp_path / "sensitivity")
    check_print_ready(png)


def test_fabric_figures_are_print_ready(tmp_path):
    from poro2d.measure.fabric import FabricRoses, orientation_histogram
    from poro2d.report.fabric_figures import plot_fabric, plot_rose

    angle = np.radians(np.linspace(0.0, 180.0, 400, endpoint=False))
    normals = np.column_stack([np.cos(angle), np.sin(angle)])
    hist = orientation_histogram(normals)
    roses = FabricRoses.of("gamma", np.array([0.0, 1.0]), [hist, hist], peak=0)
    texts = check_print_ready(plot_rose(roses, tmp_path / "rose.png", title=r"$\sigma_3$ = 100 kPa"))
    assert any("a_c" in t for t in texts)
    # where along the test a rose was taken reads as a quantity, not as the curve's column name
    shear = FabricRoses.of("shear_displacement_mm", np.array([0.0, 3.25]), [hist, hist], peak=1)
    texts = check_print_ready(plot_rose(shear, tmp_path / "shear_rose.png", title="direct shear"))
    assert not any("_mm" in t for t in texts)
    assert any("3.25 mm" in t for t in texts)
    gamma = np.linspace(0.0, 2.0, 20)
    curve = {"gamma": gamma, "a_c": 0.2 + 0 * gamma, "a_n": 0.3 + 0 * gamma, "a_t": 0.05 + 0 * gamma,
             "z_mech": 3.4 + 0 * gamma}  # fmt: skip
    check_print_ready(plot_fabric([("seed 1", curve)], tmp_path / "fabric.png", x="gamma",
                                  xlabel=r"shear strain $\gamma$", title="periodic shear"))  # fmt: skip
