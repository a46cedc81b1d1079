"""The posterior of a calibration three ways: poro2d's grid, emcee and GrainLearning's SMC.

    python benchmarks/calibration_samplers.py [RESULT_JSON] [--extra-path DIR ...] [--four]

``RESULT_JSON`` is a finished ``poro2d calibrate`` result; without it a synthetic calibration
of a known surface is made (a design, three replicates of correlated specimen noise, a
"laboratory" at a known pair). The surrogates and the noise covariance are rebuilt with
poro2d's own functions (``poro2d.calibration.model``), so every method samples the one
posterior ``poro2d calibrate`` reports. Per method it prints the marginal medians, the 95 %
central intervals, the correlation of the design coordinates, the likelihood evaluations and
the wall time. ``--four`` adds a synthetic problem of four parameters (f_p, mu_r, kn, ks):
there the grid at the calibration's resolution would need 161^4 evaluations.

emcee and GrainLearning are not poro2d's dependencies: install them apart (``pip install
--no-deps --target DIR emcee grainlearning scikit-learn joblib threadpoolctl narwhals``) and
pass ``--extra-path DIR``. A method whose package does not import is skipped with a message.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import math
import os
import sys
import time
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from itertools import combinations_with_replacement
from pathlib import Path

# one BLAS thread: the matrices here are tiny, and on a loaded machine OpenBLAS's threads made
# each of GrainLearning's Gaussian-mixture fits ten times slower (46 s against 4.9 s measured)
for _name in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

import numpy as np  # noqa: E402

from poro2d.calibration import model  # noqa: E402

LEVEL = 0.95
#: the synthetic truths in design coordinates (f_p, mu_r, kn, ks)
TRUTH = (0.45, 0.35, 0.6, 0.4)


@dataclass(frozen=True)
class Axis:
    """One calibrated parameter: its range, searched in log (f_p, kn, ks) or linearly (mu_r)."""

    name: str
    lo: float
    hi: float
    log: bool

    def value(self, u):
        u = np.asarray(u, float)
        if self.log:
            return np.exp(np.log(self.lo) + u * (np.log(self.hi) - np.log(self.lo)))
        return self.lo + u * (self.hi - self.lo)

    def unit(self, value):
        value = np.asarray(value, float)
        if self.log:
            return (np.log(value) - np.log(self.lo)) / (np.log(self.hi) - np.log(self.lo))
        return (value - self.lo) / (self.hi - self.lo)


@dataclass
class Problem:
    """A posterior over the unit cube: a flat prior, the Gaussian likelihood of poro2d's model.

    ``means``: the surrogates' values at design coordinates, (n, observables); ``precision``:
    the inverse of the misfit's covariance. ``surrogates``, ``cov``: the 2-parameter problem's
    poro2d objects, so that its grid is poro2d's own."""

    label: str
    axes: tuple[Axis, ...]
    means: Callable[[np.ndarray], np.ndarray]
    lab: np.ndarray
    precision: np.ndarray
    surrogates: list = field(default_factory=list)
    cov: np.ndarray | None = None
    truth: np.ndarray | None = None
    reported: dict | None = None  # medians and intervals the result file reports
    evaluations: int = 0

    @property
    def dim(self) -> int:
        return len(self.axes)

    def log_likelihood(self, unit: np.ndarray) -> np.ndarray:
        """The log-likelihood of design points (n, dim), as ``model.posterior`` computes it."""
        unit = np.atleast_2d(unit)
        self.evaluations += unit.shape[0]
        misfit = self.means(unit) - self.lab
        return -0.5 * np.einsum("ki,ij,kj->k", misfit, self.precision, misfit)

    def log_posterior(self, unit: np.ndarray) -> np.ndarray:
        """The log-likelihood inside the unit cube, -inf outside it (the flat prior)."""
        unit = np.atleast_2d(unit)
        inside = np.all((unit >= 0.0) & (unit <= 1.0), axis=1)
        out = np.full(unit.shape[0], -np.inf)
        if inside.any():
            out[inside] = self.log_likelihood(unit[inside])
        return out


# -- quadratic surfaces in any number of coordinates (the four-parameter problem) -----------------


def quadratic_features(unit: np.ndarray) -> np.ndarray:
    """1, the coordinates, and every product of two of them: (n, 1 + d + d(d+1)/2)."""
    unit = np.atleast_2d(unit)
    d = unit.shape[1]
    cols = [np.ones(unit.shape[0])] + [unit[:, i] for i in range(d)]
    cols += [unit[:, i] * unit[:, j] for i, j in combinations_with_replacement(range(d), 2)]
    return np.column_stack(cols)


@dataclass
class NoiseTerms:
    """What ``model.noise_covariance`` reads of a surrogate: its residual and replicates."""

    residual: float
    replicates: int


def fit_quadratic(unit: np.ndarray, values: np.ndarray) -> tuple[np.ndarray, NoiseTerms]:
    """Coefficients of a full quadratic fitted to the replicate means (points, replicates), and its
    residual corrected for the degrees of freedom, as ``model.fit_surrogate`` does in two."""
    means = values.mean(axis=1)
    features = quadratic_features(unit)
    coefficients, *_ = np.linalg.lstsq(features, means, rcond=None)
    dof = max(len(means) - features.shape[1], 1)
    residual = math.sqrt(float(np.sum((means - features @ coefficients) ** 2)) / dof)
    return coefficients, NoiseTerms(residual, values.shape[1])


# -- the problems ----------------------------------------------------------------------------------


def problem_from_result(path: Path) -> Problem:
    """The posterior of a finished calibration, rebuilt from its evaluations as ``poro2d calibrate`` does."""
    from poro2d.calibration.run import CalibrationResult
    from poro2d.calibration.units import observable_unit
    from poro2d.store import Store

    res = CalibrationResult.read(Store(path.parent)) if path.name == "result.json" else None
    if res is None:
        import json

        res = CalibrationResult.from_dict(json.loads(path.read_text()))
    ranges = model.Ranges(tuple(res.ranges.particle_friction), tuple(res.ranges.rolling_friction))
    rows = res.evaluations
    unit = ranges.to_unit([r.particle_friction for r in rows], [r.rolling_friction for r in rows])
    values = np.array([[o.values for o in r.observed] for r in rows], float)
    lab = [lab_value(obs.to_dict()) for obs in res.posterior.observables]
    surrogates = []
    for k in range(values.shape[1]):
        ok = np.isfinite(values[:, k]).any(axis=1)
        surrogates.append(model.fit_surrogate(unit[ok], values[ok, k]))
    units = [observable_unit(obs.observable) for obs in res.posterior.observables]
    cov = model.noise_covariance(
        surrogates, model.seed_covariance(values), lab, res.config.get("lab_error", 0.0), units
    )
    # the covariance's correction for being estimated (files of earlier versions: none)
    cov = cov / (res.posterior.precision_factor or 1.0)
    reported = {"median": res.posterior.median.to_dict(), "intervals": res.intervals.to_dict()}
    return two_parameter_problem(str(path), ranges, surrogates, lab, cov, reported=reported)


def lab_value(observable: dict) -> float:
    """The laboratory value of a fitted observable, whatever its unit (``lab_kpa``, ``lab_mm``)."""
    return float(next(v for k, v in observable.items() if k.startswith("lab_")))


def two_parameter_problem(label, ranges, surrogates, lab, cov, truth=None, reported=None) -> Problem:
    axes = (Axis("f_p", *ranges.fp, log=True), Axis("mu_r", *ranges.mu_r, log=False))
    return Problem(
        label,
        axes,
        lambda unit: np.column_stack([s.mean(unit) for s in surrogates]),
        np.asarray(lab, float),
        np.linalg.inv(cov),
        surrogates=surrogates,
        cov=cov,
        truth=truth,
        reported=reported,
    )


@dataclass(frozen=True)
class SyntheticDesign:
    """What a synthetic calibration is made of: the known truth and the design's size."""

    dim: int
    points: int
    replicates: int = 3
    observables: int = 6
    scatter_kpa: float = 8.0  # one specimen's seed scatter per observable
    shared: float = 0.6  # correlation of one specimen's luck across observables
    seed: int = 0


def synthetic_surface(design: SyntheticDesign) -> np.ndarray:
    """Coefficients (features, observables) of a known quadratic: strengths of 60 to 200 kPa that
    grow with every coordinate, the first two strongly and the others (kn, ks) weakly."""
    rng = np.random.default_rng(design.seed)
    d, n_obs = design.dim, design.observables
    weight = np.array([1.0, 0.7, 0.25, 0.15])[:d]
    base = np.linspace(60.0, 140.0, n_obs)
    linear = 60.0 * weight[:, None] * rng.uniform(0.3, 1.0, (d, n_obs))
    quad = [
        -15.0 * weight[i] * weight[j] * rng.uniform(0.0, 1.0, n_obs)
        for i, j in combinations_with_replacement(range(d), 2)
    ]
    return np.vstack([base[None, :], linear, np.array(quad)])


def synthetic_values(design: SyntheticDesign, truth: np.ndarray):
    """The design (points, dim), each point's replicate values (points, observables, replicates) and
    the laboratory's values (one more specimen at the truth), all seeded."""
    from scipy.stats import qmc

    rng = np.random.default_rng(design.seed + 1)
    surface = synthetic_surface(design)
    sampler = qmc.LatinHypercube(
        d=design.dim, optimization="random-cd", rng=np.random.default_rng(design.seed)
    )
    unit = sampler.random(design.points)
    n = design.observables
    luck = design.scatter_kpa**2 * (design.shared * np.ones((n, n)) + (1.0 - design.shared) * np.eye(n))
    noise = rng.multivariate_normal(np.zeros(n), luck, size=(design.points, design.replicates))
    values = (quadratic_features(unit) @ surface)[:, :, None] + noise.transpose(0, 2, 1)
    lab = quadratic_features(truth) @ surface + rng.multivariate_normal(np.zeros(n), luck)
    return unit, values, lab[0]


def synthetic_two(seed: int = 0, scatter_kpa: float = 8.0) -> Problem:
    """A calibration of (f_p, mu_r) against a known surface, through poro2d's own model functions."""
    design = SyntheticDesign(dim=2, points=18, scatter_kpa=scatter_kpa, seed=seed)
    truth = np.array(TRUTH[:2])
    unit, values, lab = synthetic_values(design, truth)
    surrogates = [model.fit_surrogate(unit, values[:, k]) for k in range(values.shape[1])]
    cov = model.noise_covariance(surrogates, model.seed_covariance(values), lab, 0.0)
    ranges = model.Ranges((0.3, 3.0), (0.0, 0.5))
    return two_parameter_problem("synthetic, 2 parameters", ranges, surrogates, lab, cov, truth=truth)


def synthetic_four(seed: int = 0) -> Problem:
    """(f_p, mu_r, kn, ks) against a known surface: a quadratic of 15 coefficients per observable."""
    design = SyntheticDesign(dim=4, points=40, observables=8, seed=seed)
    truth = np.array(TRUTH)
    unit, values, lab = synthetic_values(design, truth)
    fits = [fit_quadratic(unit, values[:, k]) for k in range(values.shape[1])]
    coefficients = np.column_stack([c for c, _ in fits])
    cov = model.noise_covariance([t for _, t in fits], model.seed_covariance(values), lab, 0.0)
    axes = (
        Axis("f_p", 0.3, 3.0, log=True),
        Axis("mu_r", 0.0, 0.5, log=False),
        Axis("kn", 1e5, 1e7, log=True),
        Axis("ks", 2.5e4, 1e7, log=True),
    )
    means = lambda unit: quadratic_features(unit) @ coefficients  # noqa: E731
    return Problem("synthetic, 4 parameters", axes, means, lab, np.linalg.inv(cov), truth=truth)


# -- the methods ------------------------------------------------------------------------------------


@dataclass
class Summary:
    """One method's answer in design coordinates: medians and central intervals per parameter."""

    method: str
    median: np.ndarray
    low: np.ndarray
    high: np.ndarray
    correlation: float
    evaluations: int
    seconds: float
    note: str = ""


def weighted_quantiles(x: np.ndarray, weights: np.ndarray, qs) -> np.ndarray:
    order = np.argsort(x)
    cdf = np.cumsum(weights[order]) / np.sum(weights)
    return np.interp(qs, cdf, x[order])


def summarize(method, samples, weights, evaluations, seconds, note="") -> Summary:
    """Medians, intervals at :data:`LEVEL` and the first two coordinates' correlation of an ensemble."""
    tail = (1.0 - LEVEL) / 2.0
    q = np.array(
        [
            [*weighted_quantiles(samples[:, i], weights, [0.5, tail, 1.0 - tail])]
            for i in range(samples.shape[1])
        ]
    )
    w = weights / weights.sum()
    mean = w @ samples
    c = (samples - mean).T @ ((samples - mean) * w[:, None])
    corr = float(c[0, 1] / math.sqrt(c[0, 0] * c[1, 1]))
    return Summary(method, q[:, 0], q[:, 1], q[:, 2], corr, evaluations, seconds, note)


def grid_two(problem: Problem) -> Summary:
    """poro2d's own posterior: ``model.posterior`` on its 161 x 161 grid."""
    ranges = model.Ranges((problem.axes[0].lo, problem.axes[0].hi), (problem.axes[1].lo, problem.axes[1].hi))
    t0 = time.perf_counter()
    post = model.posterior(ranges, problem.surrogates, problem.lab, problem.cov)
    seconds = time.perf_counter() - t0
    cols = []
    for k, name in enumerate(("fp", "mu_r")):
        lo, hi = post.interval(name, LEVEL)
        cols.append(problem.axes[k].unit([post.median(name), lo, hi]))
    q = np.array(cols)
    return Summary(
        f"grid {model.GRID}x{model.GRID}",
        q[:, 0],
        q[:, 1],
        q[:, 2],
        post.correlation(),
        model.GRID**2,
        seconds,
    )


def grid_any(problem: Problem, per_axis: int, chunk: int = 200_000) -> tuple[Summary, float]:
    """A grid of ``per_axis`` points per coordinate in any dimension, evaluated in chunks, with the
    marginal quantiles read as ``model.Posterior.interval`` reads them; also the seconds one
    evaluation costs (to price a finer grid)."""
    d = problem.dim
    axis = np.linspace(0.0, 1.0, per_axis)
    total = per_axis**d
    log_like = np.empty(total)
    t0 = time.perf_counter()
    for start in range(0, total, chunk):
        idx = np.arange(start, min(start + chunk, total))
        unit = np.column_stack([axis[(idx // per_axis**k) % per_axis] for k in range(d)])
        log_like[start : start + len(idx)] = problem.log_likelihood(unit)
    seconds = time.perf_counter() - t0
    density = np.exp(log_like - log_like.max()).reshape((per_axis,) * d)  # axis k is index (d - 1 - k)
    density /= density.sum()
    tail = (1.0 - LEVEL) / 2.0
    rows = []
    for k in range(d):
        others = tuple(a for a in range(d) if a != d - 1 - k)
        cdf = np.cumsum(density.sum(axis=others))
        rows.append([axis[min(int(np.searchsorted(cdf, p)), per_axis - 1)] for p in (0.5, tail, 1.0 - tail)])
    q = np.array(rows)
    u0 = axis[:, None] * np.ones((1, per_axis))  # coordinate 0 varies along the last index
    pair = density.sum(axis=tuple(range(d - 2)))  # (coordinate 1, coordinate 0)
    m0, m1 = float(np.sum(pair * u0.T)), float(np.sum(pair * u0))
    c00 = float(np.sum(pair * (u0.T - m0) ** 2))
    c11 = float(np.sum(pair * (u0 - m1) ** 2))
    c01 = float(np.sum(pair * (u0.T - m0) * (u0 - m1)))
    corr = c01 / math.sqrt(c00 * c11)
    label = "x".join([str(per_axis)] * d)
    return Summary(f"grid {label}", q[:, 0], q[:, 1], q[:, 2], corr, total, seconds), seconds / total


def run_emcee(emcee, problem: Problem, walkers: int, steps: int, seed: int) -> Summary:
    """emcee's affine-invariant ensemble on the same log-posterior; a chain's first quarter is burn-in."""
    rng = np.random.default_rng(seed)
    start = rng.uniform(0.05, 0.95, (walkers, problem.dim))
    problem.evaluations = 0
    t0 = time.perf_counter()
    sampler = emcee.EnsembleSampler(walkers, problem.dim, problem.log_posterior, vectorize=True)
    sampler.random_state = np.random.RandomState(seed).get_state()
    sampler.run_mcmc(start, steps, progress=False)
    seconds = time.perf_counter() - t0
    samples = sampler.get_chain(discard=steps // 4, flat=True)
    tau = float(np.max(sampler.get_autocorr_time(discard=steps // 4, quiet=True)))
    independent = samples.shape[0] / tau
    note = (
        f"{walkers} walkers x {steps} steps, autocorrelation {tau:.0f} steps, {independent:.0f} independent"
    )
    return summarize("emcee", samples, np.ones(len(samples)), problem.evaluations, seconds, note)


@dataclass(frozen=True)
class GrainLearningRun:
    """How GrainLearning's iterative Bayesian filter is run. ``exact``: the likelihood's scale never
    tempered below poro2d's (sigma >= 1 in whitened units) and each sample weighted by 1/proposal,
    so the last ensemble is the posterior ``poro2d calibrate`` reports; otherwise its defaults."""

    samples: int
    iterations: int
    exact: bool
    seed: int


def whitened(problem: Problem):
    """The simulation and observation arrays for GrainLearning's SMC: with observations o_j and a
    simulation o_j (1 + r_j), r the whitened misfit, its likelihood exp(-sum r_j^2 / (2 sigma)) is
    poro2d's at sigma = 1 (its covariance is sigma o_j^2 on the diagonal)."""
    chol = np.linalg.cholesky(np.linalg.inv(problem.precision))
    n = len(problem.lab)
    obs = 1.0 + np.arange(n, dtype=float)

    def simulate(unit: np.ndarray) -> np.ndarray:
        problem.evaluations += unit.shape[0]
        r = np.linalg.solve(chol, (problem.means(unit) - problem.lab).T).T
        return (obs * (1.0 + r))[:, :, None]

    return obs, simulate


def last_sigma(sigmas: list) -> float:
    """The last scale GrainLearning gave its likelihood (it keeps scalars and 1-element arrays)."""
    return float(np.ravel(sigmas[-1])[0])


def run_grainlearning(gl, problem: Problem, how: GrainLearningRun) -> Summary:
    """GrainLearning's ``BayesianCalibration`` with the surrogate as its simulation (a callback)."""
    obs, simulate = whitened(problem)

    def callback(calib):
        data = calib.system.param_data
        calib.system.set_sim_data(simulate(data))
        gmm = calib.inference.sampling.gmm
        if how.exact and gmm is not None:  # importance weights of the samples drawn from the last mixture
            q = np.exp(gmm.score_samples(calib.inference.sampling.normalize(data)))
            calib.inference.proposal = q / q.sum()

    calib = gl.BayesianCalibration.from_dict(
        {
            "num_iter": how.iterations,
            "callback": callback,
            "system": {
                "param_min": [0.0] * problem.dim,
                "param_max": [1.0] * problem.dim,
                "num_samples": how.samples,
                "obs_data": obs[:, None],
                "sigma_lower_bound": 1.0 if how.exact else 1e-6,
            },
            "inference": {
                "Bayes_filter": {"ess_target": 0.3},
                "sampling": {"max_num_components": 2, "random_state": how.seed},
            },
            "save_fig": -1,
        }
    )
    problem.evaluations = 0
    t0 = time.perf_counter()
    name = "GrainLearning SMC" + (" (exact)" if how.exact else " (defaults)")
    sigmas = calib.inference.sigma_list
    with contextlib.redirect_stdout(io.StringIO()), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            calib.run()
        except (ValueError, FloatingPointError, np.linalg.LinAlgError) as exc:
            raise RuntimeError(
                f"{name} failed in iteration {len(sigmas) + 1} after {problem.evaluations} evaluations"
                f" (sigma so far {', '.join(f'{last_sigma([x]):.3g}' for x in sigmas)}): {exc}"
            ) from None
    seconds = time.perf_counter() - t0
    samples = calib.inference.param_data_list[-2]  # the last ensemble weighted (the last one is unrun)
    note = f"{how.samples} samples x {len(sigmas)} iterations, last sigma {last_sigma(sigmas):.3g}"
    return summarize(name, samples, calib.inference.posterior, problem.evaluations, seconds, note)


# -- printing ---------------------------------------------------------------------------------------


def fmt(x: float) -> str:
    return f"{x:.3g}"


def print_table(problem: Problem, rows: list[Summary]) -> None:
    print(f"\n{problem.label}: {len(problem.lab)} observables")
    head = "".join(f" {a.name + ' median [95 %]':>28}" for a in problem.axes)
    print(f"{'method':<26}{head} {'corr':>6} {'evaluations':>12} {'wall s':>8}")
    for s in rows:
        cells = "".join(
            f" {fmt(a.value(m)) + ' [' + fmt(a.value(lo)) + ', ' + fmt(a.value(hi)) + ']':>28}"
            for a, m, lo, hi in zip(problem.axes, s.median, s.low, s.high, strict=True)
        )
        print(f"{s.method:<26}{cells} {s.correlation:>6.2f} {s.evaluations:>12,} {s.seconds:>8.3f}")
    for s in rows:
        if s.note:
            print(f"  {s.method}: {s.note}")
    if problem.truth is not None:
        truth = ", ".join(
            f"{a.name} {fmt(a.value(t))}" for a, t in zip(problem.axes, problem.truth, strict=True)
        )
        print(f"  truth: {truth}")


def print_agreement(reference: Summary, others: list[Summary], step: float) -> None:
    """The largest difference of each method's medians and interval ends from the reference, in grid steps."""
    for s in others:
        diff = np.max(
            np.abs(
                np.concatenate([s.median - reference.median, s.low - reference.low, s.high - reference.high])
            )
        )
        print(
            f"  {s.method}: medians and interval ends within {diff / step:.1f} grid steps"
            f" of {reference.method}"
        )


def check_rebuilt(problem: Problem, grid: Summary) -> None:
    """Says whether the rebuilt grid reproduces the intervals the result file reports."""
    if problem.reported is None or problem.reported["intervals"]["particle_friction"] is None:
        return
    names = ("particle_friction", "rolling_friction")
    ours = [
        [a.value(v) for v in (m, lo, hi)]
        for a, m, lo, hi in zip(problem.axes, grid.median, grid.low, grid.high, strict=True)
    ]
    file = [[problem.reported["median"][n], *problem.reported["intervals"][n]] for n in names]
    same = np.allclose(ours, file, rtol=1e-9)
    print(
        "  rebuilt grid "
        + ("reproduces the file's medians and intervals" if same else f"DIFFERS from the file: {file}")
    )


# -- the command ------------------------------------------------------------------------------------


def optional(name: str):
    """The optional package, or None with a message saying how to install it apart."""
    try:
        return __import__(name)
    except ImportError as exc:
        print(
            f"{name} is not importable ({exc}): skipped. Install it apart"
            f" (pip install --no-deps --target DIR {name}) and pass --extra-path DIR"
        )
        return None


def compare(problem: Problem, args, emcee, gl, grid_per_axis: int | None) -> None:
    """Every available method on one problem, printed as a table."""
    if grid_per_axis is None:
        grid = grid_two(problem)
        check_rebuilt(problem, grid)
        step = 1.0 / (model.GRID - 1)
    else:
        grid, per_eval = grid_any(problem, grid_per_axis)
        step = 1.0 / (grid_per_axis - 1)
        full = model.GRID**problem.dim
        grid.note = (
            f"at {model.GRID} per axis: {full:.3g} evaluations, about {full * per_eval / 60:.3g} min"
            f" at {per_eval * 1e9:.0f} ns each, {full * 8 / 2**30:.3g} GiB of densities"
        )
    rows = [grid]
    if emcee is not None:
        steps = args.steps * max(problem.dim // 2, 1)  # chains of 50 autocorrelation times and more
        rows.append(run_emcee(emcee, problem, args.walkers, steps, args.seed))
    failed = []
    if gl is not None:
        samples = args.gl_samples * (problem.dim // 2)
        for exact in (True, False):
            how = GrainLearningRun(samples, args.gl_iterations, exact, args.seed)
            try:
                rows.append(run_grainlearning(gl, problem, how))
            except RuntimeError as exc:  # its answer is then no answer: say so beside the table
                failed.append(str(exc))
    print_table(problem, rows)
    for line in failed:
        print(f"  {line}")
    print_agreement(grid, rows[1:], step)


def versions(emcee, gl) -> str:
    from importlib.metadata import PackageNotFoundError, version

    import poro2d

    parts = [f"poro2d {poro2d.__version__}", f"numpy {np.__version__}"]
    for mod, name in ((emcee, "emcee"), (gl, "grainlearning"), (gl, "scikit-learn")):
        if mod is not None:
            with contextlib.suppress(PackageNotFoundError):
                parts.append(f"{name} {version(name)}")
    return ", ".join(parts)


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument(
        "result", nargs="?", type=Path, help="a calibration's result.json (default: a synthetic one)"
    )
    ap.add_argument(
        "--extra-path", action="append", default=[], help="a folder emcee or GrainLearning is installed in"
    )
    ap.add_argument("--four", action="store_true", help="also the four-parameter synthetic problem")
    ap.add_argument("--walkers", type=int, default=32)
    ap.add_argument("--steps", type=int, default=8000, help="emcee steps per walker per 2 parameters")
    ap.add_argument(
        "--gl-samples", type=int, default=200, help="GrainLearning's samples per iteration per 2 parameters"
    )
    ap.add_argument("--gl-iterations", type=int, default=8)
    ap.add_argument("--grid4", type=int, default=41, help="points per axis of the four-parameter grid")
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args(argv)
    sys.path[:0] = [str(Path(p).resolve()) for p in args.extra_path]
    emcee, gl = optional("emcee"), optional("grainlearning")
    print(versions(emcee, gl))
    problem = problem_from_result(args.result) if args.result else synthetic_two(args.seed)
    compare(problem, args, emcee, gl, None)
    if args.four:
        compare(synthetic_four(args.seed), args, emcee, gl, args.grid4)


if __name__ == "__main__":
    main()
