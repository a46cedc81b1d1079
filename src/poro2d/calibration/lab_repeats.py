"""Repeats of a laboratory programme: the same direct shear tests run again on new specimens.

A laboratory that repeats its tests (the same normal stresses, the same readings) measures
its own scatter and averages it down. A calibration handed several such series fits the mean
of their values, and the laboratory's share of the noise shrinks with their number
(:func:`poro2d.calibration.model.noise_covariance`).

That share is the scatter of one simulated specimen unless the repeats say otherwise: the
laboratory specimen is taken as one more realisation of the packing. When the repeats scatter
more than the simulated specimens do, the whole share is scaled up by the ratio of the two
(:func:`lab_scatter_ratio`), so a laboratory noisier than its model never buys narrow intervals.

Repeats are distinct measurements: a series given twice (the same file, or a copy under another
name or saved again) would halve the laboratory's share with no scatter, so it is refused
(:func:`check_distinct`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from poro2d.errors import InputError
from poro2d.shear.lab import LabData, read_lab_csv
from poro2d.shear.parts import LabPeak, LabRecord


@dataclass(frozen=True)
class LabRepeats:
    """One or more laboratory series of the same programme; ``series[0]`` names the data."""

    series: tuple[LabData, ...]

    @classmethod
    def of(cls, lab) -> LabRepeats:
        """The series of ``lab``: one CSV or ``LabData``, or a list of them (each a repeat)."""
        items = list(lab) if isinstance(lab, list | tuple) else [lab]
        if not items:
            raise InputError("--lab", "[]", "one laboratory CSV, or several repeats of one programme")
        series = tuple(x if isinstance(x, LabData) else read_lab_csv(x) for x in items)
        check_same_programme(series)
        check_distinct(series)
        return cls(series)

    @property
    def first(self) -> LabData:
        return self.series[0]

    @property
    def count(self) -> int:
        return len(self.series)

    @property
    def source(self) -> str:
        return "; ".join(s.source for s in self.series)

    def normal_stresses(self) -> list[float]:
        return self.first.normal_stresses()

    def record(self) -> LabRecord:
        """The data as ``result.json`` keeps them: one series as its file; repeats as their
        sources and the mean peak of every normal stress (the values fitted)."""
        if self.count == 1:
            return self.first.record()
        peaks = [
            LabPeak(
                normal_stress_kpa=s, peak_shear_stress_kpa=float(np.mean([x.peaks[s] for x in self.series]))
            )
            for s in self.first.normal_stresses()
        ]
        return LabRecord(source=self.source, kind=self.first.kind, peaks=peaks)


def check_same_programme(series: tuple[LabData, ...]) -> None:
    """Refuse repeats that are not one programme: every series the same normal stresses, the
    same kind (peaks or curves) and, with curves, the plate's rise in all or in none."""
    first = series[0]
    for other in series[1:]:
        for what, a, b in (
            ("normal stresses", first.normal_stresses(), other.normal_stresses()),
            ("kind", first.kind, other.kind),
            ("vertical_displacement_mm column", bool(first.vertical), bool(other.vertical)),
        ):
            if a != b:
                raise InputError(
                    "--lab", other.source,
                    f"a repeat of {first.source}: the same {what} ({_text(a)}, this file {_text(b)})",
                )  # fmt: skip


def check_distinct(series: tuple[LabData, ...]) -> None:
    """Refuse a series whose readings are those of an earlier one: the same measurement counted
    twice would narrow the intervals as a real repeat does, with no scatter to show for it."""
    for k, other in enumerate(series):
        for first in series[:k]:
            if same_readings(first, other):
                raise InputError(
                    "--lab", other.source, f"a repeat with readings of its own, not those of {first.source}",
                    "the same measurement twice is one laboratory series; give it once",
                )  # fmt: skip


def same_readings(a: LabData, b: LabData) -> bool:
    """Whether two series hold the same numbers: peaks, and every curve and rise reading."""
    if a.peaks != b.peaks or a.curves.keys() != b.curves.keys() or a.vertical.keys() != b.vertical.keys():
        return False
    curves = all(np.array_equal(a.curves[s][i], b.curves[s][i]) for s in a.curves for i in (0, 1))
    return curves and all(np.array_equal(a.vertical[s], b.vertical[s]) for s in a.vertical)


def _text(value) -> str:
    if isinstance(value, list):
        return ", ".join(f"{v:g} kPa" for v in value)
    if isinstance(value, bool):
        return "present" if value else "absent"
    return str(value)


def mean_targets(
    per_series: list[list[tuple[str, float, float]]],
) -> tuple[list[tuple[str, float, float]], np.ndarray]:
    """The targets fitted (each value the mean over the series) and every series' values
    (series x targets), from the targets of each series in the same order."""
    keys = [(obs, s) for obs, s, _ in per_series[0]]
    values = np.array([[y for *_, y in targets] for targets in per_series], float)
    mean = values.mean(axis=0)
    return [(obs, s, float(y)) for (obs, s), y in zip(keys, mean, strict=True)], values


def lab_scatter_ratio(values: np.ndarray, seed_cov: np.ndarray) -> float | None:
    """The laboratory repeats' variance over one simulated specimen's, pooled over the observables.

    ``values``: series x targets; ``seed_cov``: the simulated specimens' covariance of the same
    targets. The mean over the observables of each one's sample variance across the series over
    its seed variance: about 1 when the laboratory scatters as a simulated specimen does. None
    with a single series (nothing to compare) or no seed scatter."""
    if values.shape[0] < 2:
        return None
    seed_var = np.diag(seed_cov)
    ok = seed_var > 0.0
    if not ok.any():
        return None
    lab_var = values.var(axis=0, ddof=1)
    return float(np.mean(lab_var[ok] / seed_var[ok]))


def lab_share(repeats: int, ratio: float | None) -> float:
    """The laboratory mean's share of the seed covariance: one specimen's scatter (scaled up by
    ``ratio`` when the repeats scatter more) over the number of repeats."""
    return max(1.0, ratio or 1.0) / repeats


__all__ = [
    "LabRepeats",
    "check_distinct",
    "check_same_programme",
    "lab_scatter_ratio",
    "lab_share",
    "mean_targets",
]
