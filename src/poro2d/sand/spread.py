"""How far another run of ``poro2d sand`` may land: the answer's standard error.

The answer is the mean interior porosity of ``seeds`` specimens prepared at one friction,
mu_prep. Two samplings of chaotic packings set it, and the spread of the specimens (their sd
over seeds) shows only the second:

1. **The calibration.** mu_prep is read off the seed means of a few specimens a friction: the
   ends set the 2D target (Dr mapped onto them), the frictions around it the inversion
   (:mod:`poro2d.criterion.density`). Other calibration seeds give another mu_prep
   (:func:`~poro2d.criterion.density.friction_error`), and the specimens follow it by the slope
   of interior porosity against friction (:func:`interior_slope`).
2. **The specimens** at that friction: sd / sqrt(n).

Their sum in quadrature is the answer's standard error: two runs from independent seeds differ
by about sqrt(2) times it (docs/sand.md measures it on Toyoura sand).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from poro2d.criterion.density import Calibration, friction_error
from poro2d.typed_result import TypedResult


def _mean(values: list[float | None]) -> float:
    v = [x for x in values if x is not None and math.isfinite(x)]
    return float(np.mean(v)) if v else math.nan


def interior_slope(mus: list[float], interior: list[list[float | None]], mu_prep: float,
                   cal: Calibration) -> float:  # fmt: skip
    """d(interior porosity) / d(mu_prep) around ``mu_prep``: between the two calibrated frictions
    that hold it, from their seed means of the interior porosity (``interior``, per friction of
    ``mus``). Without two frictions that have one, the slope of the calibration's fit of n'
    (the box porosity) stands in. The magnitude: the answer moves with mu_prep either way."""
    pts = [(mu, m) for mu, m in zip(mus, map(_mean, interior or []), strict=False) if math.isfinite(m)]
    if len(pts) < 2:
        usable = cal.usable()
        pts = list(zip(usable.mus, usable.fitted, strict=True))
    xs = [p[0] for p in pts]
    j = int(np.clip(np.searchsorted(xs, mu_prep, side="right"), 1, len(pts) - 1))
    (x0, y0), (x1, y1) = pts[j - 1], pts[j]
    return abs((y1 - y0) / (x1 - x0))


@dataclass(eq=False)
class AnswerError(TypedResult):
    """The answer's standard error and its two parts (``answer_error`` in ``sand.json``).

    ``specimens_se``: sd of the accepted specimens' interior porosity / sqrt(n);
    ``mu_prep_se``: the friction's standard error from the calibration's seeds;
    ``interior_slope``: d(interior)/d(mu_prep) around mu_prep (calibration box);
    ``calibration_se``: their product, the answer's share from the calibration;
    ``answer_se``: both in quadrature. None where the seeds give no spread (one seed a friction).
    """

    specimens_se: float | None
    mu_prep_se: float | None
    interior_slope: float | None
    calibration_se: float | None
    answer_se: float | None

    @classmethod
    def of(cls, dr: float, cal: Calibration, mus: list[float], interior: list[list[float | None]],
           mu_prep: float, interiors: list[float]) -> AnswerError:  # fmt: skip
        """From the calibration (``cal``; ``interior`` per friction of ``mus``), the state's ``dr``
        and ``mu_prep``, and the accepted specimens' interior porosities."""
        v = np.array([x for x in interiors if x is not None and math.isfinite(x)], dtype=float)
        spec = float(v.std(ddof=1) / math.sqrt(v.size)) if v.size > 1 else math.nan
        mu_se = friction_error(dr, cal)
        slope = interior_slope(mus, interior, mu_prep, cal)
        cal_se = slope * mu_se
        total = math.hypot(spec, cal_se)

        def num(x: float) -> float | None:
            return float(x) if math.isfinite(x) else None

        return cls(num(spec), num(mu_se), num(slope), num(cal_se), num(total))

    def text(self) -> str:
        """One line: the standard error and its parts, or why there is none."""
        if self.answer_se is None:
            return "standard error: n/a (one seed a friction or one specimen: no spread to read)"
        return (
            f"standard error {self.answer_se:.4f} (specimens {self.specimens_se:.4f}; the calibration's "
            f"seeds {self.calibration_se:.4f}, through mu_prep +- {self.mu_prep_se:.4f})"
        )


__all__ = ["AnswerError", "interior_slope"]
