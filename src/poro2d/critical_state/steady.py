"""The steady state read off a series: its means, their standard errors, and the drift check.

Over the window gamma >= ``window_start`` the stress ratio is the ratio of the mean shear
stress to the mean normal stress (a mean of ratios would weigh the low-pressure rows more);
its standard error comes from ``blocks`` consecutive blocks of equal strain, each a mean of
about independent stretches once a block spans more than the correlation strain (a few
tenths): SE = sd(block values) / sqrt(blocks). The window counts as steady only if neither
the stress ratio nor the solid fraction drifts: their least-squares slope against gamma times
the window's width stays within the case's limits. A run that is not steady reports its
numbers with ``steady`` false and says why: they are not the critical state.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from poro2d.critical_state.series import CellSeries
from poro2d.typed_result import TypedResult


@dataclass(eq=False)
class SteadyState(TypedResult):
    """What the window says: means, standard errors over blocks, drifts, whether it is steady, the
    window (gamma from its start to the last row) and its rows; the first keys of a run's
    ``result.json`` (:class:`~poro2d.critical_state.results.CriticalStateTestResult`)."""

    stress_ratio: float
    stress_ratio_se: float
    friction_angle_deg: float
    solid_fraction: float
    solid_fraction_se: float
    inertial_number: float
    coordination: float
    normal_stress_kpa: float
    stress_ratio_drift: float
    solid_fraction_drift: float
    steady: bool
    note: str
    window: list[float]
    rows: int


def _drift(gamma: np.ndarray, values: np.ndarray) -> float:
    """Least-squares slope times the window's width: how much the value moved across it."""
    slope = np.polyfit(gamma, values, 1)[0]
    return float(slope * (gamma[-1] - gamma[0]))


def _block_se(values: list[float]) -> float:
    v = np.asarray(values)
    return float(v.std(ddof=1) / math.sqrt(v.size))


def read_steady(
    series: CellSeries, window_start: float, blocks: int, mu_limit: float, phi_limit: float
) -> SteadyState:
    """The steady state of ``series`` over gamma >= window_start (see the module docstring)."""
    m = series.window(window_start)
    g = series.gamma[m]
    tau, sig = series.shear_stress_kpa[m], series.normal_stress_kpa[m]
    phi = series.solid_fraction[m]
    parts = np.array_split(np.arange(g.size), blocks)
    mu_blocks = [float(tau[p].mean() / sig[p].mean()) for p in parts]
    phi_blocks = [float(phi[p].mean()) for p in parts]
    mu_drift = _drift(g, series.stress_ratio[m])
    phi_drift = _drift(g, phi)
    problems = []
    if abs(mu_drift) > mu_limit:
        problems.append(f"the stress ratio drifts by {mu_drift:+.3f} over the window (limit {mu_limit:g})")
    if abs(phi_drift) > phi_limit:
        problems.append(
            f"the solid fraction drifts by {phi_drift:+.4f} over the window (limit {phi_limit:g})"
        )
    note = "steady: no drift of the stress ratio or the solid fraction over the window"
    if problems:
        note = (
            "not steady: "
            + "; ".join(problems)
            + " (a larger strain, or more disks: a small cell's slow swings read as drift)"
        )
    mu = float(tau.mean() / sig.mean())
    return SteadyState(
        stress_ratio=mu,
        stress_ratio_se=_block_se(mu_blocks),
        friction_angle_deg=math.degrees(math.atan(mu)),
        solid_fraction=float(phi.mean()),
        solid_fraction_se=_block_se(phi_blocks),
        inertial_number=float(series.inertial_number[m].mean()),
        coordination=float(series.coordination[m].mean()),
        normal_stress_kpa=float(sig.mean()),
        stress_ratio_drift=mu_drift,
        solid_fraction_drift=phi_drift,
        steady=not problems,
        note=note,
        window=[window_start, float(series.gamma[-1])],
        rows=int(g.size),
    )


__all__ = ["SteadyState", "read_steady"]
