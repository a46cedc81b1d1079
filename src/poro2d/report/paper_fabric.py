"""The paper report's section on fabric and coordination of the direct shear tests.

Per normal stress of the first specimen: the contact anisotropy a_c, the force anisotropies a_n
and a_t and the mechanical coordination Z_m (:class:`~poro2d.measure.fabric.Fabric`, the trailing
columns of every test's ``curve.csv``) at the smoothed peak of the shear stress and at the end of
the test, each smoothed over the peak window as the peak itself is; their spread over the
replicate specimens (:class:`~poro2d.measure.spread.Spread`); and the stress-force-fabric check of
Rothenburg & Bathurst (1989), (a_c + a_n + a_t) / 2 beside the measured tau / sigma at the peak.
Everything is read off the series' curves as the run computed or read them back; a curve of an
earlier poro2d, without fabric columns, gives "not recorded".
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from poro2d.measure.spread import Spread
from poro2d.report.document import Block
from poro2d.report.fabric_figures import has_fabric
from poro2d.shear.fit import peak, smooth
from poro2d.shear.results import ShearSeriesResult

#: the report's name of the series' ``fabric.png`` among the shear figures
FABRIC_CURVES = "fabric_curves"
#: the fabric's quantities: curve column and the report's name of it
QUANTITIES = (("a_c", "a_c"), ("a_n", "a_n"), ("a_t", "a_t"), ("z_mech", "Z_m"))
#: digits shown: the anisotropies to three, the coordination to two
DIGITS = {"a_c": 3, "a_n": 3, "a_t": 3, "z_mech": 2}


def rose_figure(normal_stress_kpa: float) -> str:
    """The report's name of a test's ``fabric_rose.png`` among the shear figures."""
    return f"fabric_rose_{normal_stress_kpa:g}"


@dataclass(frozen=True)
class FabricState:
    """The fabric of one test at one point of its curve: where (shear displacement, mm) and
    a_c, a_n, a_t, Z_m there, smoothed over the peak window."""

    at_mm: float
    a_c: float
    a_n: float
    a_t: float
    z_mech: float

    @property
    def stress_ratio(self) -> float:
        """(a_c + a_n + a_t) / 2: the stress ratio the fabric and forces give (Rothenburg & Bathurst 1989)."""
        return 0.5 * (self.a_c + self.a_n + self.a_t)


@dataclass(frozen=True)
class ShearTestFabric:
    """One test's fabric at its peak and at its end, and its measured tau / sigma at the peak."""

    normal_stress_kpa: float
    peak: FabricState
    end: FabricState
    peak_stress_ratio: float


def _smoothed(x: np.ndarray, y: np.ndarray, window: float) -> np.ndarray:
    """The moving average of ``y`` over the finite values only (a NaN row, a state without
    force-carrying contacts, must not spoil its neighbours' averages)."""
    finite = np.isfinite(y)
    total = smooth(x, np.where(finite, y, 0.0), window)
    count = smooth(x, finite.astype(float), window)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(count > 0.0, total / count, math.nan)


def _state(x_mm: np.ndarray, curve: Mapping[str, np.ndarray], k: int, window: float) -> FabricState:
    """The fabric at record ``k``, every quantity smoothed over ``window`` (m)."""
    x = 1e-3 * x_mm
    values = {col: float(_smoothed(x, np.asarray(curve[col], float), window)[k]) for col, _ in QUANTITIES}
    return FabricState(at_mm=float(x_mm[k]), **values)


def fabric_of(series: ShearSeriesResult, normal_stress_kpa: float) -> ShearTestFabric | None:
    """The fabric of ``series``' test at ``normal_stress_kpa``; None when its curve did not record it."""
    curve = series.curves.get(normal_stress_kpa)
    if not has_fabric(curve):
        return None
    window = series.settings.peak_window
    x_mm = np.asarray(curve["shear_displacement_mm"], float)
    k = peak(1e-3 * x_mm, curve["shear_stress_kpa"], window).index
    ratio = next(t.peak_stress_ratio for t in series.tests if t.normal_stress_kpa == normal_stress_kpa)
    end = _state(x_mm, curve, len(x_mm) - 1, window)
    return ShearTestFabric(normal_stress_kpa, _state(x_mm, curve, k, window), end, ratio)


def series_fabric(series: ShearSeriesResult) -> list[ShearTestFabric]:
    """Every test of ``series`` whose curve recorded the fabric, by normal stress."""
    found = (fabric_of(series, s) for s in sorted(series.normal_stresses_kpa))
    return [t for t in found if t is not None]


def fabric_blocks(series: Mapping[str, ShearSeriesResult], figures: Mapping[str, Path]) -> list[Block]:
    """The section: the first specimen's fabric at peak and end per normal stress, its spread over
    the specimens, the stress-force-fabric check and the figures (``figures``: by the names
    :data:`FABRIC_CURVES` and :func:`rose_figure`)."""
    b: list[Block] = [("h2", "Fabric and coordination of the direct shear tests")]
    specimens = {label: series_fabric(s) for label, s in series.items()}
    first = next(iter(specimens.values()), [])
    if not first:
        b.append(("p", "Fabric and coordination: not recorded (the tests' curves hold no fabric columns: "
                       "they were written by a poro2d that did not record them)."))  # fmt: skip
        return b
    b.append(("p", FABRIC_TEXT))
    b.append(("table", ["normal stress (kPa)", "at", "shear displacement (mm)", *(n for _, n in QUANTITIES)],
              [row for t in first for row in _first_rows(t)]))  # fmt: skip
    b += _spread_blocks(specimens)
    b += _stress_fabric_blocks(first, specimens)
    if FABRIC_CURVES in figures:
        caption = "a_c, a_n, a_t and Z_m against shear displacement, the first specimen's tests"
        b.append(("img", figures[FABRIC_CURVES], caption))
    for t in first:
        name = rose_figure(t.normal_stress_kpa)
        if name in figures:
            caption = (
                f"Contact orientations at the peak and at the end, {t.normal_stress_kpa:g} kPa (first "
                "specimen), with the second-order Fourier fit of that one record's histogram (the table's "
                "values are smoothed over the peak window)"
            )
            b.append(("img", figures[name], caption))
    return b


#: what the section's numbers are
FABRIC_TEXT = (
    "The fabric of the first specimen's tests, from the force-carrying disk-disk contacts "
    "(docs/fabric.md): a_c, the second-order anisotropy of the contact orientations; a_n and a_t, "
    "those of the normal and tangential forces; Z_m, the mechanical coordination, force-carrying "
    "contacts per disk once the rattlers are removed. Each value is smoothed over the peak window, "
    "at the record of the smoothed peak of the shear stress and at the last record."
)


def _first_rows(t: ShearTestFabric) -> list[list]:
    """A test's two rows of the first specimen's table: at the peak and at the end."""
    return [
        [t.normal_stress_kpa, at, round(s.at_mm, 2), *(_text(getattr(s, col), col) for col, _ in QUANTITIES)]
        for at, s in (("peak", t.peak), ("end", t.end))
    ]


def _text(value: float, col: str) -> str:
    return "-" if not math.isfinite(value) else f"{value:.{DIGITS[col]}f}"


def _over_specimens(specimens: Mapping[str, list[ShearTestFabric]], sigma: float, value) -> Spread | None:
    """``value(test)`` over the specimens' tests at ``sigma`` (finite values only); None for fewer
    than two."""
    found = [value(t) for tests in specimens.values() for t in tests if t.normal_stress_kpa == sigma]
    found = [v for v in found if math.isfinite(v)]
    return Spread.of(found) if len(found) > 1 else None


def _spread_text(
    specimens: Mapping[str, list[ShearTestFabric]], t: ShearTestFabric, at: str, col: str
) -> str:
    """Column ``col`` at ``at`` (peak or end) of the tests at ``t``'s normal stress, over the specimens."""
    over = _over_specimens(specimens, t.normal_stress_kpa, lambda u: getattr(getattr(u, at), col))
    return "-" if over is None else over.text(DIGITS[col])


def _spread_blocks(specimens: Mapping[str, list[ShearTestFabric]]) -> list[Block]:
    """The table over the replicate specimens (mean +- sd (min-max)), when there are two or more."""
    recorded = [label for label, tests in specimens.items() if tests]
    if len(recorded) < 2:
        return []
    rows = []
    for t in next(iter(specimens.values())):
        for at in ("peak", "end"):
            rows.append(
                [t.normal_stress_kpa, at, *(_spread_text(specimens, t, at, col) for col, _ in QUANTITIES)]
            )
    return [
        ("p", f"Over the {len(recorded)} specimens ({', '.join(recorded)}): mean +- sd (min-max)."),
        ("table", ["normal stress (kPa)", "at", *(n for _, n in QUANTITIES)], rows),
    ]


#: the stress-force-fabric relation, what it assumes, and why it is only approximate here
STRESS_FABRIC_TEXT = (
    "Stress-force-fabric check (Rothenburg & Bathurst 1989, Geotechnique 39(4), 601-614): in a 2D "
    "assembly, to second order in the Fourier series of the contact orientations and forces, with "
    "every branch vector of one length and the anisotropies coaxial with the stress, "
    "q / p = (a_c + a_n + a_t) / 2, with q / p = (sigma_1 - sigma_3) / (sigma_1 + sigma_3). The "
    "relation is approximate: it neglects the branch lengths' anisotropy and the higher harmonics, "
    "and the box measures tau / sigma on the horizontal plane of the upper half, which is q / p "
    "only where the principal axes lie at 45 degrees to that plane and the horizontal and vertical "
    "stresses are equal (simple shear at the critical state), while the anisotropies are those of "
    "the whole specimen; were the horizontal plane the plane of maximum obliquity, tau / sigma "
    "would be tan phi_m while q / p = sin phi_m, smaller. The ratio of the two says how far that "
    "picture holds at the peak."
)


def _stress_fabric_blocks(
    first: list[ShearTestFabric], specimens: Mapping[str, list[ShearTestFabric]]
) -> list[Block]:
    """(a_c + a_n + a_t) / 2 at the peak beside the measured tau / sigma, per normal stress."""
    many = sum(bool(tests) for tests in specimens.values()) > 1
    rows = []
    for t in first:
        estimate = t.peak.stress_ratio
        ratio = estimate / t.peak_stress_ratio if t.peak_stress_ratio else math.nan
        row = [t.normal_stress_kpa, _ratio(estimate), _ratio(t.peak_stress_ratio), _ratio(ratio)]
        if many:
            over = _over_specimens(
                specimens, t.normal_stress_kpa, lambda u: u.peak.stress_ratio / u.peak_stress_ratio
            )
            row.append("-" if over is None else over.text(2))
        rows.append(row)
    head = ["normal stress (kPa)", "(a_c + a_n + a_t) / 2 at the peak", "tau / sigma at the peak (measured)",
            "ratio of the two"]  # fmt: skip
    head += ["ratio over the specimens"] if many else []
    return [("p", STRESS_FABRIC_TEXT), ("table", head, rows)]


def _ratio(value: float) -> str:
    return "-" if not math.isfinite(value) else f"{value:.3f}"


__all__ = [
    "FABRIC_CURVES",
    "FabricState",
    "ShearTestFabric",
    "fabric_blocks",
    "rose_figure",
    "fabric_of",
    "series_fabric",
]
