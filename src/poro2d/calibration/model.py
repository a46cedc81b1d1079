"""The statistics of a calibration: design, surrogate, posterior (numpy, scipy and emcee).

The parameters live in design coordinates: log(f_p) (the strength of a packing grows
with the logarithm of its friction far more evenly than with the friction itself) and
mu_r, each scaled to [0, 1] over its range; when the disks' stiffnesses are calibrated too,
log(kn) and log(ks) (a stiffness spans decades, and a packing's response follows its
logarithm), scaled likewise.

* design: a Latin hypercube over the unit square (or cube, in d coordinates:
  ``scipy.stats.qmc``), seeded;
* surrogate: per observable (a peak or an end shear stress at one normal stress, or the
  plate's rise at the end of the test: the dilation), a
  full quadratic in the d coordinates fitted by least squares to the replicate means;
  the seed scatter is pooled over the design points; what the quadratic cannot follow
  (its residual) is counted as extra noise;
* posterior: a flat prior on the unit square, a Gaussian likelihood of the laboratory
  values, evaluated on a grid (two parameters: the grid is exact, no sampler to tune); in
  three or four coordinates a grid of the same resolution would cost 161^d evaluations, so the
  posterior is sampled with emcee's affine-invariant ensemble (:func:`sampled_posterior`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from poro2d.calibration.discrepancy import Discrepancy, level_posterior, log_likelihood
from poro2d.record import Record

#: points per axis of the posterior grid
GRID = 161
#: a credible interval wider than this fraction of its range is reported as poorly identified
WIDE_FRACTION = 0.5
#: the axes of a posterior, in the order of the design coordinates: particle friction, rolling
#: friction, and the disks' normal and shear stiffness when they are calibrated
AXES = ("fp", "mu_r", "kn", "ks")
#: the axes searched in the logarithm of the parameter
LOG_AXES = ("fp", "kn", "ks")


@dataclass(frozen=True)
class Ranges:
    """The search ranges of particle friction f_p (> 0) and rolling friction mu_r (>= 0), and
    optionally of the disks' normal and shear stiffness kn, ks (N/m, > 0; None: not calibrated)."""

    fp: tuple[float, float]
    mu_r: tuple[float, float]
    kn: tuple[float, float] | None = None
    ks: tuple[float, float] | None = None

    @property
    def axes(self) -> tuple[str, ...]:
        """The calibrated parameters' axes (:data:`AXES`), in the order of the design coordinates."""
        return tuple(a for a in AXES if getattr(self, a) is not None)

    @property
    def dim(self) -> int:
        return len(self.axes)

    def _span(self, axis: str) -> tuple[float, float]:
        """The range of ``axis`` in its design coordinate's scale (the logarithm on :data:`LOG_AXES`)."""
        lo, hi = getattr(self, axis)
        return (np.log(lo), np.log(hi)) if axis in LOG_AXES else (lo, hi)

    def to_unit(self, *values) -> np.ndarray:
        """(n, d) design coordinates of parameter values (f_p, mu_r, then kn, ks as calibrated)."""
        columns = []
        for axis, x in zip(self.axes, values, strict=True):
            lo, hi = self._span(axis)
            x = np.asarray(x, float)
            columns.append(np.atleast_1d(((np.log(x) if axis in LOG_AXES else x) - lo) / (hi - lo)))
        return np.column_stack(columns)

    def from_unit(self, unit: np.ndarray) -> tuple[np.ndarray, ...]:
        """(f_p, mu_r, then kn, ks as calibrated) arrays of design coordinates."""
        unit = np.atleast_2d(unit)
        values = []
        for k, axis in enumerate(self.axes):
            lo, hi = self._span(axis)
            x = lo + unit[:, k] * (hi - lo)
            values.append(np.exp(x) if axis in LOG_AXES else x)
        return tuple(values)

    def axis_values(self, axis: str, unit_values: np.ndarray) -> np.ndarray:
        """The parameter values of one axis at design coordinates ``unit_values`` of it."""
        unit = np.full((len(unit_values), self.dim), 0.0)
        unit[:, self.axes.index(axis)] = unit_values
        return self.from_unit(unit)[self.axes.index(axis)]


def rounded(*columns: np.ndarray) -> list[tuple[float, ...]]:
    """Parameter tuples (f_p, mu_r, then kn, ks as calibrated) rounded to 4 significant digits:
    the identity of a shear test in the cache."""
    return [tuple(float(f"{x:.4g}") for x in row) for row in zip(*columns, strict=True)]


def space_filling(ranges: Ranges, n: int, seed: int) -> list[tuple[float, ...]]:
    """``n`` parameter tuples of a Latin hypercube (optimised for its centred discrepancy)."""
    from scipy.stats import qmc

    sampler = qmc.LatinHypercube(d=ranges.dim, optimization="random-cd", rng=np.random.default_rng(seed))
    return rounded(*ranges.from_unit(sampler.random(n)))


def _features(unit: np.ndarray) -> np.ndarray:
    """The full quadratic's terms: 1, each coordinate, then each product x_i x_j (i <= j) in
    order (two coordinates u, v: 1, u, v, uu, uv, vv)."""
    d = unit.shape[1]
    columns = [np.ones_like(unit[:, 0]), *(unit[:, i] for i in range(d))]
    columns += [unit[:, i] * unit[:, j] for i in range(d) for j in range(i, d)]
    return np.column_stack(columns)


def n_coefficients(d: int) -> int:
    """The coefficients of a full quadratic in ``d`` coordinates: (d + 1)(d + 2) / 2."""
    return (d + 1) * (d + 2) // 2


#: the coefficients of the two-parameter quadratic
N_COEFFICIENTS = n_coefficients(2)


@dataclass(eq=False)
class Surrogate(Record):
    """A quadratic response surface of one observable's replicate mean, and its noise terms.

    ``scatter``: the seed standard deviation pooled over the design; ``residual``: the root
    mean square misfit of the quadratic to the means, corrected for its degrees of freedom
    (both in the observable's ``unit``: kPa for a stress, mm for the dilation, ``ratio`` for a
    dimensionless one); ``replicates``: the specimens per design point.

    It is also its entry of a calibration file's ``fit``: the noise terms under keys named by
    the unit (``seed_scatter_kpa``, ``surrogate_residual_kpa``), after ``replicates`` but for a
    stress, whose keys were the first ones and stay before it.
    """

    coefficients: np.ndarray
    scatter: float
    residual: float
    replicates: int
    unit: str = "kPa"

    def layout(self) -> tuple:
        u = self.unit.lower()
        noise = ((f"seed_scatter_{u}", "scatter"), (f"surrogate_residual_{u}", "residual"))
        if u == "kpa":
            return ("coefficients", *noise, "replicates")
        return ("coefficients", "replicates", *noise)

    @classmethod
    def from_dict(cls, data) -> Surrogate:
        """A surrogate read back from its entry of a file's ``fit`` (its unit named by the keys)."""
        key = next((k for k in data if k.startswith("seed_scatter_")), "seed_scatter_kpa")
        u = key.removeprefix("seed_scatter_")
        unit = {"kpa": "kPa"}.get(u, u)
        noise = data.get(key), data.get(f"surrogate_residual_{u}")
        return cls(np.asarray(data["coefficients"], float), *noise, data.get("replicates", 0), unit)

    def mean(self, unit: np.ndarray) -> np.ndarray:
        return _features(np.atleast_2d(unit)) @ self.coefficients


def fit_surrogate(unit: np.ndarray, values: np.ndarray, measured_in: str = "kPa") -> Surrogate:
    """The surrogate of one observable in unit ``measured_in``: ``values`` (design points x
    replicates; NaN: failed) at the design points ``unit``."""
    means = np.nanmean(values, axis=1)
    counts = np.sum(np.isfinite(values), axis=1)
    coefficients, *_ = np.linalg.lstsq(_features(unit), means, rcond=None)
    misfit = means - _features(unit) @ coefficients
    dof = max(len(means) - n_coefficients(unit.shape[1]), 1)
    residual = math.sqrt(float(np.sum(misfit**2)) / dof)
    several = counts > 1
    if several.any():  # pooled variance: each point's sum of squares over its degrees of freedom
        ss = np.nansum((values[several] - means[several, None]) ** 2)
        scatter = math.sqrt(float(ss) / float(np.sum(counts[several] - 1)))
    else:
        scatter = 0.0
    return Surrogate(coefficients, scatter, residual, int(np.max(counts)), measured_in)


@dataclass(kw_only=True)
class NoiseTerms:
    """What the caller records beside a posterior: the noise it was computed with."""

    noise_sd: list[float] = field(default_factory=list)  # per observable (its unit)
    noise_correlation: list[list[float]] = field(default_factory=list)
    precision_factor: float = 1.0  # the covariance's correction for being estimated
    lab_repeats: int = 1  # laboratory series averaged
    lab_scatter_ratio: float | None = None  # their scatter over a simulated specimen's (repeats only)
    discrepancy: Discrepancy | None = None  # the model-discrepancy term (None: none)
    discrepancy_weights: np.ndarray | None = None  # its levels' posterior (sums to 1)

    def discrepancy_at(self, q: float) -> float | None:
        """The quantile ``q`` of the discrepancy size s (noise sd) under the posterior (None: no term)."""
        if self.discrepancy is None or self.discrepancy_weights is None:
            return None
        return self.discrepancy.level_at(self.discrepancy_weights, q)


@dataclass
class Posterior(NoiseTerms):
    """The posterior on the grid of design coordinates (``density`` sums to 1)."""

    ranges: Ranges
    u: np.ndarray  # grid coordinates of log f_p, [0, 1]
    v: np.ndarray  # and of mu_r
    density: np.ndarray  # (len(v), len(u))

    def finite(self) -> bool:
        return bool(np.isfinite(self.density).all())

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


def posterior(
    ranges: Ranges,
    surrogates: list[Surrogate],
    lab_values,
    cov: np.ndarray,
    discrepancy: Discrepancy | None = None,
) -> Posterior:
    """The grid posterior of (f_p, mu_r) given the laboratory values (one per surrogate), the
    covariance of their misfit (:func:`noise_covariance`) and the model-discrepancy term
    (:mod:`poro2d.calibration.discrepancy`; None: none), integrated over its levels."""
    u = np.linspace(0.0, 1.0, GRID)
    v = np.linspace(0.0, 1.0, GRID)
    uu, vv = np.meshgrid(u, v)
    points = np.column_stack([uu.ravel(), vv.ravel()])
    misfit = np.column_stack([s.mean(points) - y for s, y in zip(surrogates, lab_values, strict=True)])
    log_like, terms = log_likelihood(cov, discrepancy)(misfit)
    log_like -= log_like.max()
    density = np.exp(log_like).reshape(uu.shape)
    post = Posterior(ranges, u, v, density / density.sum())
    if terms is not None:
        post.discrepancy, post.discrepancy_weights = discrepancy, level_posterior(terms)
    return post


#: walkers of the ensemble sampler (emcee's rule: at least twice the parameters; 32 as measured
#: in docs/calibration.md, for 2 to 4 parameters)
WALKERS = 32
#: the chain's first length (steps of every walker); a quarter of the chain is discarded as burn-in
CHAIN_STEPS = 2000
#: the chain, burn-in discarded, must be this many autocorrelation times long (emcee's own default):
#: its estimate of the autocorrelation time is reliable only then
AUTOCORR_MULTIPLE = 50
#: the longest chain: doubled from CHAIN_STEPS until long enough, refused beyond
MAX_CHAIN_STEPS = 64_000


@dataclass
class SampledPosterior(NoiseTerms):
    """The posterior in d > 2 design coordinates as emcee's chain (burn-in discarded).

    ``chain``: (samples, d) design coordinates, every walker's steps after the burn-in;
    ``log_prob``: each sample's log posterior (up to a constant); ``steps``, ``burn_in``:
    of each walker; ``autocorrelation``: the integrated autocorrelation time per coordinate (steps).
    """

    ranges: Ranges
    chain: np.ndarray
    log_prob: np.ndarray
    steps: int
    burn_in: int
    autocorrelation: list[float]
    walkers: int = WALKERS

    def finite(self) -> bool:
        return bool(np.isfinite(self.chain).all() and np.isfinite(self.log_prob).all())

    def best(self) -> tuple[float, ...]:
        """The chain's sample of the highest posterior (f_p, mu_r, kn, ks as calibrated)."""
        row = self.chain[int(np.argmax(self.log_prob))]
        return tuple(float(x[0]) for x in self.ranges.from_unit(row))

    def interval(self, axis: str, level: float) -> tuple[float, float]:
        """The central credible interval of one parameter's marginal: the chain's quantiles."""
        tail = (1.0 - level) / 2.0
        q = np.quantile(self.chain[:, self.ranges.axes.index(axis)], [tail, 1.0 - tail])
        lo, hi = self.ranges.axis_values(axis, q)
        return float(lo), float(hi)

    def median(self, axis: str) -> float:
        return self.interval(axis, 0.0)[0]

    def correlation(self, a: str = "fp", b: str = "mu_r") -> float:
        """The posterior correlation of two design coordinates (near +-1: a ridge)."""
        axes = self.ranges.axes
        return float(np.corrcoef(self.chain[:, axes.index(a)], self.chain[:, axes.index(b)])[0, 1])

    def draw(self, n: int, seed: int) -> list[tuple[float, ...]]:
        """Up to ``n`` distinct samples of the chain (the second round's design): the chain is
        distributed as the posterior, so each sample is equally likely."""
        rng = np.random.default_rng(seed)
        picks = rng.choice(len(self.chain), size=min(n, len(self.chain)), replace=False)
        return list(dict.fromkeys(rounded(*self.ranges.from_unit(self.chain[picks]))))


def log_posterior(
    surrogates: list[Surrogate], lab_values, cov: np.ndarray, discrepancy: Discrepancy | None = None
):
    """The log posterior of design coordinates ``x`` (walkers x d; a flat prior on the unit cube):
    the Gaussian log-likelihood of the laboratory values (summed over the discrepancy's levels),
    -inf outside the cube."""
    lab = np.asarray(lab_values, float)
    likelihood = log_likelihood(cov, discrepancy)

    def log_prob(x: np.ndarray) -> np.ndarray:
        misfit = np.column_stack([s.mean(x) for s in surrogates]) - lab
        inside = np.all((x >= 0.0) & (x <= 1.0), axis=1)
        return np.where(inside, likelihood(misfit)[0], -np.inf)

    return log_prob


def sampled_posterior(
    ranges: Ranges, surrogates: list[Surrogate], lab_values, cov: np.ndarray, seed: int,
    steps: int = CHAIN_STEPS, discrepancy: Discrepancy | None = None,
) -> SampledPosterior:  # fmt: skip
    """The posterior of d > 2 parameters sampled by emcee's ensemble on the surrogates.

    The walkers start uniform in the unit cube; the sampler's own random state and the start
    come from ``seed``, so the same inputs give the same chain bit for bit. The chain is doubled
    until its part after the burn-in (a quarter) spans :data:`AUTOCORR_MULTIPLE` autocorrelation
    times; a chain still shorter at :data:`MAX_CHAIN_STEPS` is refused (its intervals would be
    the sampler's noise, not the posterior's).
    """
    import emcee

    rng = np.random.default_rng(seed)
    start = rng.random((WALKERS, ranges.dim))
    log_prob = log_posterior(surrogates, lab_values, cov, discrepancy)
    sampler = emcee.EnsembleSampler(WALKERS, ranges.dim, log_prob, vectorize=True)
    sampler.random_state = np.random.RandomState(int(rng.integers(2**32))).get_state()
    sampler.run_mcmc(start, steps, progress=False)
    while True:
        burn = steps // 4
        tau = sampler.get_autocorr_time(discard=burn, tol=0)
        if np.all(np.isfinite(tau)) and steps - burn >= AUTOCORR_MULTIPLE * float(tau.max()):
            break
        if 2 * steps > MAX_CHAIN_STEPS:
            raise RuntimeError(
                f"the posterior chain of {WALKERS} walkers x {steps} steps spans only"
                f" {(steps - burn) / float(np.nanmax(tau)):.0f} autocorrelation times"
                f" (needs {AUTOCORR_MULTIPLE}): no answer is reported"
            )
        sampler.run_mcmc(None, steps, progress=False)
        steps *= 2
    post = SampledPosterior(
        ranges,
        sampler.get_chain(discard=burn, flat=True),
        sampler.get_log_prob(discard=burn, flat=True),
        steps,
        burn,
        [float(t) for t in tau],
    )
    if discrepancy is not None and not discrepancy.none:
        misfit = np.column_stack([s.mean(post.chain) for s in surrogates]) - np.asarray(lab_values, float)
        _, terms = log_likelihood(cov, discrepancy)(misfit)
        weights = np.full(len(post.chain), 1.0 / len(post.chain))
        post.discrepancy, post.discrepancy_weights = discrepancy, level_posterior(terms, weights)
    return post


__all__ = [
    "AXES",
    "GRID",
    "SampledPosterior",
    "n_coefficients",
    "sampled_posterior",
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
