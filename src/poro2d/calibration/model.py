"""The statistics of a calibration: design, surrogate, posterior (numpy and scipy only).

The parameters live in design coordinates: log(f_p) (the strength of a packing grows
with the logarithm of its friction far more evenly than with the friction itself) and
mu_r, each scaled to [0, 1] over its range.

* design: a Latin hypercube over the unit square (``scipy.stats.qmc``), seeded;
* surrogate: per observable (a peak or an end shear stress at one normal stress, or the
  plate's rise at the end of the test: the dilation), a
  full quadratic in the two coordinates fitted by least squares to the replicate means;
  the seed scatter is pooled over the design points; what the quadratic cannot follow
  (its residual) is counted as extra noise;
* posterior: a flat prior on the unit square, a Gaussian likelihood of the laboratory
  values, evaluated on a grid (two parameters: the grid is exact, no sampler to tune).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

#: points per axis of the posterior grid
GRID = 161
#: a credible interval wider than this fraction of its range is reported as poorly identified
WIDE_FRACTION = 0.5


@dataclass(frozen=True)
class Ranges:
    """The search ranges of particle friction f_p (> 0) and rolling friction mu_r (>= 0)."""

    fp: tuple[float, float]
    mu_r: tuple[float, float]

    def to_unit(self, fp, mu_r) -> np.ndarray:
        """(n, 2) design coordinates of parameter values."""
        lo, hi = np.log(self.fp[0]), np.log(self.fp[1])
        u = (np.log(np.asarray(fp, float)) - lo) / (hi - lo)
        v = (np.asarray(mu_r, float) - self.mu_r[0]) / (self.mu_r[1] - self.mu_r[0])
        return np.column_stack([np.atleast_1d(u), np.atleast_1d(v)])

    def from_unit(self, unit: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(f_p, mu_r) arrays of design coordinates."""
        unit = np.atleast_2d(unit)
        lo, hi = np.log(self.fp[0]), np.log(self.fp[1])
        fp = np.exp(lo + unit[:, 0] * (hi - lo))
        mu_r = self.mu_r[0] + unit[:, 1] * (self.mu_r[1] - self.mu_r[0])
        return fp, mu_r


def rounded(fp: np.ndarray, mu_r: np.ndarray) -> list[tuple[float, float]]:
    """Parameter pairs rounded to 4 significant digits: the identity of a shear test in the cache."""
    return [(float(f"{a:.4g}"), float(f"{b:.4g}")) for a, b in zip(fp, mu_r, strict=True)]


def space_filling(ranges: Ranges, n: int, seed: int) -> list[tuple[float, float]]:
    """``n`` parameter pairs of a Latin hypercube (optimised for its centred discrepancy)."""
    from scipy.stats import qmc

    sampler = qmc.LatinHypercube(d=2, optimization="random-cd", rng=np.random.default_rng(seed))
    return rounded(*ranges.from_unit(sampler.random(n)))


def _features(unit: np.ndarray) -> np.ndarray:
    u, v = unit[:, 0], unit[:, 1]
    return np.column_stack([np.ones_like(u), u, v, u * u, u * v, v * v])


N_COEFFICIENTS = 6


@dataclass
class Surrogate:
    """A quadratic response surface of one observable's replicate mean, and its noise terms.

    ``scatter``: the seed standard deviation pooled over the design; ``residual``: the root
    mean square misfit of the quadratic to the means, corrected for its degrees of freedom
    (both in the observable's unit: kPa for a stress, mm for the dilation); ``replicates``:
    the specimens per design point.
    """

    coefficients: np.ndarray
    scatter: float
    residual: float
    replicates: int

    def mean(self, unit: np.ndarray) -> np.ndarray:
        return _features(np.atleast_2d(unit)) @ self.coefficients


def fit_surrogate(unit: np.ndarray, values: np.ndarray) -> Surrogate:
    """The surrogate of one observable: ``values`` (design points x replicates; NaN: failed)."""
    means = np.nanmean(values, axis=1)
    counts = np.sum(np.isfinite(values), axis=1)
    coefficients, *_ = np.linalg.lstsq(_features(unit), means, rcond=None)
    misfit = means - _features(unit) @ coefficients
    dof = max(len(means) - N_COEFFICIENTS, 1)
    residual = math.sqrt(float(np.sum(misfit**2)) / dof)
    several = counts > 1
    if several.any():  # pooled variance: each point's sum of squares over its degrees of freedom
        ss = np.nansum((values[several] - means[several, None]) ** 2)
        scatter = math.sqrt(float(ss) / float(np.sum(counts[several] - 1)))
    else:
        scatter = 0.0
    return Surrogate(coefficients, scatter, residual, int(np.max(counts)))


@dataclass
class Posterior:
    """The posterior on the grid of design coordinates (``density`` sums to 1)."""

    ranges: Ranges
    u: np.ndarray  # grid coordinates of log f_p, [0, 1]
    v: np.ndarray  # and of mu_r
    density: np.ndarray  # (len(v), len(u))
    noise_sd: list[float] = field(default_factory=list)  # per observable (its unit), set by the caller
    noise_correlation: list[list[float]] = field(default_factory=list)
    precision_factor: float = 1.0  # the covariance's correction for being estimated, set by the caller
    lab_repeats: int = 1  # laboratory series averaged, set by the caller
    lab_scatter_ratio: float | None = None  # their scatter over a simulated specimen's (repeats only)

    @property
    def fp_values(self) -> np.ndarray:
        return self.ranges.from_unit(np.column_stack([self.u, np.zeros_like(self.u)]))[0]

    @property
    def mu_r_values(self) -> np.ndarray:
        return self.ranges.from_unit(np.column_stack([np.zeros_like(self.v), self.v]))[1]

    def best(self) -> tuple[float, float]:
        """The posterior's maximum (f_p, mu_r)."""
        j, i = np.unravel_index(int(np.argmax(self.density)), self.density.shape)
        return float(self.fp_values[i]), float(self.mu_r_values[j])

    def interval(self, axis: str, level: float) -> tuple[float, float]:
        """The central credible interval of one parameter's marginal ("fp" or "mu_r")."""
        marginal = self.density.sum(axis=0) if axis == "fp" else self.density.sum(axis=1)
        values = self.fp_values if axis == "fp" else self.mu_r_values
        cdf = np.cumsum(marginal)
        tail = (1.0 - level) / 2.0
        lo = values[min(int(np.searchsorted(cdf, tail)), len(values) - 1)]
        hi = values[min(int(np.searchsorted(cdf, 1.0 - tail)), len(values) - 1)]
        return float(lo), float(hi)

    def median(self, axis: str) -> float:
        """The median of one parameter's marginal ("fp" or "mu_r")."""
        return self.interval(axis, 0.0)[0]

    def correlation(self) -> float:
        """The posterior correlation of the design coordinates (near +-1: a ridge)."""
        uu, vv = np.meshgrid(self.u, self.v)
        p = self.density
        mu, mv = float(np.sum(p * uu)), float(np.sum(p * vv))
        cuu = float(np.sum(p * (uu - mu) ** 2))
        cvv = float(np.sum(p * (vv - mv) ** 2))
        cuv = float(np.sum(p * (uu - mu) * (vv - mv)))
        return cuv / math.sqrt(cuu * cvv) if cuu > 0 and cvv > 0 else 0.0

    def draw(self, n: int, seed: int) -> list[tuple[float, float]]:
        """``n`` distinct grid points drawn from the posterior (the second round's design)."""
        rng = np.random.default_rng(seed)
        flat = self.density.ravel()
        n = min(n, int(np.count_nonzero(flat)))
        picks = rng.choice(flat.size, size=n, replace=False, p=flat)
        j, i = np.unravel_index(picks, self.density.shape)
        return rounded(self.fp_values[i], self.mu_r_values[j])


#: weight of the diagonal in the pooled covariance: a few replicates give a noisy estimate of
#: the off-diagonal terms, so they are shrunk towards zero by this fraction
SHRINK = 0.2


def seed_covariance(values: np.ndarray) -> np.ndarray:
    """The covariance of one specimen's deviations across observables (each in its unit: kPa^2
    between stresses, mm^2 between dilations, kPa mm across).

    ``values``: (design points, observables, replicates); design points with a missing
    test are left out. Deviations from each point's replicate mean, pooled over the points
    (degrees of freedom: replicates - 1 per point), then shrunk by :data:`SHRINK`.
    """
    complete = np.isfinite(values).all(axis=(1, 2))
    v = values[complete]
    n_obs = values.shape[1]
    if v.shape[0] == 0 or v.shape[2] < 2:
        return np.zeros((n_obs, n_obs))
    dev = v - v.mean(axis=2, keepdims=True)  # (points, observables, replicates)
    flat = dev.transpose(0, 2, 1).reshape(-1, n_obs)
    cov = flat.T @ flat / (v.shape[0] * (v.shape[2] - 1))
    return (1.0 - SHRINK) * cov + SHRINK * np.diag(np.diag(cov))


def noise_covariance(
    surrogates: list[Surrogate],
    seed_cov: np.ndarray,
    lab_values,
    lab_error: float,
    units=None,
    lab_share: float = 1.0,
) -> np.ndarray:
    """The covariance of the misfit between the laboratory values and the surrogates.

    The laboratory specimen is one more realisation (``seed_cov``; the mean of several laboratory
    repeats ``lab_share`` times it, :func:`poro2d.calibration.lab_repeats.lab_share`), the mean of the
    replicates is uncertain too (``seed_cov / replicates``), each quadratic misses by its
    residual and the laboratory reading carries ``lab_error`` (a fraction of each value, so in
    its unit). The observables may be in different units (``units``: one label per observable;
    None: all in kPa): the likelihood's Mahalanobis distance does not depend on them, and the
    small ridge added to the diagonal against a singular matrix (:func:`_ridge`) is scaled per
    unit, so that the stresses' kPa^2 do not swamp the dilations' mm^2.
    """
    replicates = max(max(s.replicates for s in surrogates), 1)
    extra = [s.residual**2 + (lab_error * y) ** 2 for s, y in zip(surrogates, lab_values, strict=True)]
    cov = seed_cov * (lab_share + 1.0 / replicates) + np.diag(extra)
    labels = np.array(["kPa" if units is None else units[k] for k in range(len(extra))])
    ridge = np.zeros(len(extra))
    for label in dict.fromkeys(labels):
        same = labels == label
        ridge[same] = _ridge(float(np.trace(cov[np.ix_(same, same)])), label)
    return cov + np.diag(ridge)


def _ridge(trace: float, unit: str) -> float:
    """1e-9 of the trace of one unit's block: far below any noise, enough to invert a singular one.

    The stresses keep their floor of 1 kPa^2 (a block of zeros gets 1e-9 kPa^2); another unit
    is floored only where its block is zero, so that its ridge scales with it: the same
    dilation in mm or in m gives the same posterior."""
    if unit == "kPa":
        return 1e-9 * max(trace, 1.0)
    return 1e-9 * (trace if trace > 0.0 else 1.0)


def precision_factor(dof: int, observables: int) -> float:
    """The factor (dof - p - 1) / dof that makes the inverse of an estimated covariance unbiased.

    The noise covariance is estimated from the replicates' deviations (``dof``: complete design
    points x (replicates - 1)). Inverted, an estimate from few degrees of freedom overstates
    the precision, the more so the more observables ``p`` it spans: the mean of the inverse of a
    Wishart estimate is dof / (dof - p - 1) times the true precision (Hartlap, Simon & Schneider
    2007, A&A 464:399). Without it, many readings of a curve on three replicates give intervals
    that miss a known truth; the factor widens them by sqrt(dof / (dof - p - 1)). Zero or less:
    too many observables for the replicates, no honest interval.
    """
    return (dof - observables - 1) / dof if dof > 0 else 0.0


def posterior(ranges: Ranges, surrogates: list[Surrogate], lab_values, cov: np.ndarray) -> Posterior:
    """The grid posterior of (f_p, mu_r) given the laboratory values (one per surrogate) and
    the covariance of their misfit (:func:`noise_covariance`)."""
    u = np.linspace(0.0, 1.0, GRID)
    v = np.linspace(0.0, 1.0, GRID)
    uu, vv = np.meshgrid(u, v)
    points = np.column_stack([uu.ravel(), vv.ravel()])
    misfit = np.column_stack([s.mean(points) - y for s, y in zip(surrogates, lab_values, strict=True)])
    precision = np.linalg.inv(cov)
    log_like = -0.5 * np.einsum("ki,ij,kj->k", misfit, precision, misfit)
    log_like -= log_like.max()
    density = np.exp(log_like).reshape(uu.shape)
    return Posterior(ranges, u, v, density / density.sum())


__all__ = [
    "GRID",
    "WIDE_FRACTION",
    "Posterior",
    "Ranges",
    "Surrogate",
    "fit_surrogate",
    "noise_covariance",
    "seed_covariance",
    "posterior",
    "precision_factor",
    "rounded",
    "space_filling",
]
