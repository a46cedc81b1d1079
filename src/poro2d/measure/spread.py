"""One number over replicate specimens or seeds: a granular packing is chaotic, so a result is
reported with its spread, never as one sample.

:class:`Spread` is the record every study writes for it (``mean``, ``sd``, ``min``, ``max``,
``values``): the critical state's numbers over seeds, the biaxial test's angles over replicates.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from poro2d.typed_result import TypedResult


@dataclass(eq=False)
class Spread(TypedResult):
    """One number over the replicates: mean, sample sd (None for one value), min, max and each value."""

    mean: float
    sd: float | None
    min: float
    max: float
    values: list[float]

    @classmethod
    def of(cls, values: list[float]):
        v = np.asarray(values, float)
        sd = float(v.std(ddof=1)) if v.size > 1 else None
        return cls(float(v.mean()), sd, float(v.min()), float(v.max()), [float(x) for x in v])

    def text(self, digits: int = 3, unit: str = "") -> str:
        """``0.276 +- 0.004 (0.271-0.280)``, or ``0.276`` for one value (``unit`` after the mean's sd)."""
        if self.sd is None or not math.isfinite(self.sd):
            return f"{self.mean:.{digits}f}{unit}"
        return (
            f"{self.mean:.{digits}f} +- {self.sd:.{digits}f}{unit} "
            f"({self.min:.{digits}f}-{self.max:.{digits}f})"
        )


__all__ = ["Spread"]
