"""The paper report's fabric section, on series whose curves are known in closed form."""

import json
import math
from pathlib import Path

import numpy as np
import pytest

from poro2d.measure.fabric import FABRIC_COLUMNS
from poro2d.report.document import to_markdown
from poro2d.report.paper_fabric import FABRIC_CURVES, fabric_blocks, fabric_of, rose_figure
from poro2d.shear.curve import CURVE_COLUMNS, ShearCurve
from poro2d.shear.results import ShearSeriesResult

DATA = Path(__file__).parents[1] / "data" / "before_typed_results"
#: the stored series' tests: 50 and 100 kPa, peak window 0.5 mm
SIGMAS = (50.0, 100.0)
X_MM = 0.04 * np.arange(151)  # a record every 0.04 mm: no window's edge falls on a record
X_PEAK_MM = X_MM[50]  # 2 mm


def curve(sigma: float, a_c: float, slope: float = 0.0, fabric: bool = True) -> ShearCurve:
    """A curve whose shear stress peaks at 2 mm (a parabola: its smoothed peak is there too), a_c
    linear in the displacement (``a_c`` at the peak: a centred average keeps a line's value), a_n
    and a_t fixed multiples of a_c and Z_m = 3 + a_c; without ``fabric`` the columns of an earlier
    poro2d (NaN)."""
    tau = sigma * (0.8 - 0.1 * (X_MM - X_PEAK_MM) ** 2)
    line = a_c + slope * (X_MM - X_PEAK_MM)
    columns = {name: np.zeros_like(X_MM) for name in CURVE_COLUMNS}
    columns |= {
        "shear_displacement_mm": X_MM,
        "shear_stress_kpa": tau,
        "normal_stress_kpa": np.full_like(X_MM, sigma),
    }
    values = {"a_c": line, "a_n": 1.5 * line, "a_t": 0.5 * line, "z_mech": 3.0 + line}
    for name in FABRIC_COLUMNS:
        columns[name] = values.get(name, np.zeros_like(X_MM)) if fabric else np.full_like(X_MM, math.nan)
    rows = [{k: float(v[i]) for k, v in columns.items()} for i in range(len(X_MM))]
    return ShearCurve.of_rows(rows)


def series(a_c: dict[float, float], *, slope: float = 0.0, fabric: bool = True) -> ShearSeriesResult:
    """The stored series (two tests) with curves of contact anisotropy ``a_c`` by normal stress at the
    peak, each test's tau / sigma at the peak set to 0.8 (the parabola's top)."""
    data = json.loads((DATA / "shear_series_result.json").read_text())
    for t in data["tests"]:
        t["peak_stress_ratio"] = 0.8
    res = ShearSeriesResult.from_dict(data)
    res.curves = {s: curve(s, a_c[s], slope, fabric) for s in SIGMAS}
    return res


def test_peak_and_end_values_are_read_where_the_smoothed_peak_lies():
    t = fabric_of(series({50.0: 0.2, 100.0: 0.3}, slope=0.01), 50.0)
    assert t.peak.at_mm == pytest.approx(X_PEAK_MM)
    # a line averaged over a centred window keeps its value: the peak's a_c is a_c itself
    assert (t.peak.a_c, t.peak.a_n, t.peak.a_t, t.peak.z_mech) == pytest.approx((0.2, 0.3, 0.1, 3.2))
    # at the end the window is cut to its left half: the last 7 records (0.24 mm), their mean 0.12 mm back
    end = 0.2 + 0.01 * (X_MM[-1] - 0.12 - X_PEAK_MM)
    assert t.end.at_mm == pytest.approx(X_MM[-1]) and t.end.a_c == pytest.approx(end)
    # (a_c + a_n + a_t) / 2 = (1 + 1.5 + 0.5) a_c / 2
    assert t.peak.stress_ratio == pytest.approx(1.5 * 0.2) and t.peak_stress_ratio == 0.8


def test_a_nan_row_does_not_spoil_its_neighbours():
    res = series({50.0: 0.2, 100.0: 0.3})
    a_c = res.curves[50.0]["a_c"]
    a_c[0] = math.nan  # a state without force-carrying contacts at the start
    assert fabric_of(res, 50.0).peak.a_c == pytest.approx(0.2)


def test_the_section_gives_the_first_specimen_the_spread_and_the_stress_fabric_check(tmp_path):
    specimens = {
        "seed0": series({50.0: 0.2, 100.0: 0.3}),
        "seed1": series({50.0: 0.3, 100.0: 0.3}),
        "seed2": series({50.0: 0.4, 100.0: 0.3}),
    }
    figures = {FABRIC_CURVES: tmp_path / "fabric.png", rose_figure(50.0): tmp_path / "rose.png"}
    text = to_markdown(fabric_blocks(specimens, figures), tmp_path)
    # the first specimen's rows: 50 kPa at the peak, a_c 0.2, a_n 0.3, a_t 0.1, Z_m 3.2
    assert "| 50 | peak | 2 | 0.200 | 0.300 | 0.100 | 3.20 |" in text
    # over the three specimens at 50 kPa: a_c 0.2, 0.3, 0.4 -> mean 0.3, sd 0.1
    assert "0.300 +- 0.100 (0.200-0.400)" in text
    assert "Over the 3 specimens (seed0, seed1, seed2)" in text
    # the check: (a_c + a_n + a_t) / 2 = 1.5 a_c = 0.3 against tau / sigma 0.8
    assert f"| 50 | 0.300 | 0.800 | {0.3 / 0.8:.3f} |" in text
    assert "Rothenburg & Bathurst 1989" in text and "approximate" in text
    assert "(fabric.png)" in text and "(rose.png)" in text


def test_one_specimen_has_no_spread_table():
    text = to_markdown(fabric_blocks({"seed0": series({50.0: 0.2, 100.0: 0.3})}, {}), Path("."))
    assert "Over the" not in text and "ratio over the specimens" not in text
    assert "| 100 | peak | 2 | 0.300 | 0.450 | 0.150 | 3.30 |" in text


def test_curves_of_an_earlier_poro2d_say_not_recorded():
    old = {"seed0": series({50.0: 0.2, 100.0: 0.3}, fabric=False)}
    blocks = fabric_blocks(old, {FABRIC_CURVES: Path("fabric.png")})
    text = to_markdown(blocks, Path("."))
    assert "not recorded" in text and "| a_c |" not in text and "fabric.png" not in text
    assert fabric_of(old["seed0"], 50.0) is None
