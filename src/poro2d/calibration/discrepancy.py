"""The model-discrepancy term of a calibration: a laboratory specimen is not a packing of 2D disks.

Kennedy & O'Hagan (2001, J. R. Stat. Soc. B 63:425) write an observation as the model at the
true parameters, plus the model's discrepancy, plus the observation's own error. The noise
covariance C of :func:`poro2d.calibration.model.noise_covariance` holds every term but the
discrepancy: it is right for a laboratory made by poro2d itself, and too narrow for one whose
values no (f_p, mu_r) reproduces within the seed scatter.

Here the discrepancy is independent between observables, with a standard deviation of ``s``
times the observable's own noise sd (the square root of C's diagonal): the likelihood's
covariance becomes C + s^2 diag(C). The unit is the noise, not the observable's value, because
the values can be near zero (a volumetric strain, a rise) where a discrepancy is not, and
because what a discrepancy does to a posterior depends on its size beside the noise alone.
``s`` is not known: it gets a uniform prior over :data:`LEVELS` (0 to 4 noise sd) and is
integrated out, the likelihood of a parameter point being the prior-weighted sum over the levels.

Where the model fits the laboratory within C, the large levels pay for their determinant and the
small ones carry the posterior; where no parameter point fits, the levels that explain the misfit
take over and the intervals widen. A discrepancy that a wrong (f_p, mu_r) can absorb (softer
contacts read as less friction) is not seen in the misfit at all; the prior's larger levels widen
the intervals against it all the same. Measured coverage: docs/calibration.md.

Modes: ``estimate`` (the above); ``none`` (C alone: the intervals of earlier versions, bit for
bit); ``auto`` (the default: ``none`` for a laboratory file poro2d wrote itself, its
:mod:`poro2d.calibration.synthetic` header says so, ``estimate`` for any other); a number fixes
``s`` (in noise sd, up to :data:`MAX_FIXED`), for example from a validation study's held-out errors.
"""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np

from poro2d.errors import InputError, is_number
from poro2d.io_utils import read_utf8
from poro2d.typed_result import TypedResult

#: the discrepancy sizes s (in noise sd) integrated over (``estimate``): a uniform prior from 0 to 4
LEVELS = np.linspace(0.0, 4.0, 41)
#: the largest fixed size (noise sd)
MAX_FIXED = 10.0
#: the modes besides a fixed size
MODES = ("auto", "estimate", "none")
#: how the header of a laboratory file poro2d wrote itself begins (:mod:`poro2d.calibration.synthetic`)
SYNTHETIC_HEADER = "# SYNTHETIC laboratory data"


def check_mode(mode) -> str | float:
    """``auto``, ``estimate``, ``none`` or a fixed size in noise sd in (0, :data:`MAX_FIXED`], as
    given (a numeric string is read); anything else an InputError naming ``--discrepancy``."""
    if isinstance(mode, str) and mode.strip().lower() in MODES:
        return mode.strip().lower()
    value = mode
    if isinstance(mode, str):
        try:
            value = float(mode)
        except ValueError:
            value = None
    if is_number(value) and 0.0 < float(value) <= MAX_FIXED:
        return float(value)
    raise InputError(
        "--discrepancy", mode, f"auto, estimate, none, or a size in noise sd in (0, {MAX_FIXED:g}]"
    )


def made_by_poro2d(lab) -> bool:
    """Whether ``lab`` (a path, or a list of them) is laboratory data poro2d wrote itself: every
    file's first line is the synthetic header. Data handed over as values are not known to be."""
    paths = lab if isinstance(lab, list | tuple) else [lab]
    if not paths:
        return False
    for path in paths:
        if not isinstance(path, str | os.PathLike):
            return False
        try:
            text = read_utf8("--lab", path, "a laboratory CSV file")
        except InputError:  # the calibration's own reader says what is wrong with it
            return False
        if not text.startswith(SYNTHETIC_HEADER):
            return False
    return True


def resolve_mode(mode, lab) -> str | float:
    """The mode a calibration against ``lab`` runs with: ``auto`` made ``none`` or ``estimate``."""
    mode = check_mode(mode)
    if mode != "auto":
        return mode
    return "none" if made_by_poro2d(lab) else "estimate"


@dataclass(frozen=True)
class Discrepancy:
    """The levels of ``s`` (noise sd) a likelihood sums over and their prior log weights."""

    levels: np.ndarray
    log_weights: np.ndarray

    @classmethod
    def of(cls, mode) -> Discrepancy:
        """The term of ``mode`` (``estimate``, ``none`` or a fixed size; ``auto`` resolved first)."""
        mode = check_mode(mode)
        if mode == "auto":
            raise ValueError("resolve the auto mode against the laboratory first (resolve_mode)")
        if mode == "none":
            levels = np.zeros(1)
        elif mode == "estimate":
            levels = LEVELS
        else:
            levels = np.array([float(mode)])
        return cls(levels, np.full(len(levels), -np.log(len(levels))))

    @property
    def none(self) -> bool:
        """No discrepancy: the likelihood is the noise covariance's alone."""
        return len(self.levels) == 1 and self.levels[0] == 0.0

    def covariances(self, cov: np.ndarray) -> np.ndarray:
        """The covariance at every level, C + s^2 diag(C), stacked (levels, n, n)."""
        noise = np.diag(np.diag(cov))
        return np.stack([cov + s**2 * noise for s in self.levels])

    def level_at(self, weights: np.ndarray, q: float) -> float:
        """The quantile ``q`` of ``s`` under the posterior ``weights`` over the levels (summing to 1)."""
        cdf = np.cumsum(weights)
        return float(self.levels[min(int(np.searchsorted(cdf, q)), len(self.levels) - 1)])

    def saturated(self, weights: np.ndarray, level: float) -> bool:
        """Whether the posterior's upper ``level`` quantile of ``s`` is the prior's top level: the
        laboratory may lie further from the model than the term allows."""
        return len(self.levels) > 1 and self.level_at(weights, 1.0 - (1.0 - level) / 2.0) >= self.levels[-1]


@dataclass(frozen=True)
class Levels:
    """The discrepancy's levels made ready for many likelihoods: each level's precision and its
    log prior weight less half its log determinant."""

    precisions: np.ndarray  # (levels, n, n)
    offsets: np.ndarray  # (levels,)

    @classmethod
    def of(cls, cov: np.ndarray, discrepancy: Discrepancy) -> Levels:
        covs = discrepancy.covariances(cov)
        logdets = np.array([np.linalg.slogdet(c)[1] for c in covs])
        return cls(np.linalg.inv(covs), discrepancy.log_weights - 0.5 * logdets)

    def terms(self, misfit: np.ndarray) -> np.ndarray:
        """The log of prior weight times Gaussian likelihood of each misfit row (rows, n) at each
        level: (rows, levels)."""
        terms = np.empty((misfit.shape[0], len(self.offsets)))
        for j, precision in enumerate(self.precisions):
            terms[:, j] = self.offsets[j] - 0.5 * np.sum((misfit @ precision) * misfit, axis=1)
        return terms

    def log_likelihood(self, misfit: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The log likelihood of each misfit row, summed over the levels, and the terms per level."""
        terms = self.terms(misfit)
        top = terms.max(axis=1, keepdims=True)
        top = np.where(np.isfinite(top), top, 0.0)
        return (top + np.log(np.sum(np.exp(terms - top), axis=1, keepdims=True)))[:, 0], terms


def log_likelihood(cov: np.ndarray, discrepancy: Discrepancy | None):
    """The function of misfit rows that gives the log likelihood of each (up to a constant) and the
    log terms per level, the covariance inverted once for many calls (None terms without a
    discrepancy: then it is -0.5 m' C^-1 m exactly, as before the term existed)."""
    if discrepancy is None or discrepancy.none:
        precision = np.linalg.inv(cov)
        return lambda misfit: (-0.5 * np.einsum("ki,ij,kj->k", misfit, precision, misfit), None)
    return Levels.of(cov, discrepancy).log_likelihood


def level_posterior(terms: np.ndarray, row_weights: np.ndarray | None = None) -> np.ndarray:
    """The posterior over the levels (summing to 1) from the per-level log terms of rows that are
    a uniform grid (``row_weights`` None) or a chain's samples (each row's weight: the level
    responsibilities are averaged, the chain being distributed as the posterior)."""
    if row_weights is None:
        flat = np.exp(terms - terms.max())
        w = flat.sum(axis=0)
    else:
        resp = np.exp(terms - terms.max(axis=1, keepdims=True))
        resp /= resp.sum(axis=1, keepdims=True)
        w = (resp * row_weights[:, None]).sum(axis=0)
    return w / w.sum()


@dataclass(eq=False)
class DiscrepancyRecord(TypedResult):
    """What ``result.json`` keeps of the discrepancy term (``posterior.discrepancy``): its size
    ``s`` in each observable's noise sd, its prior, its posterior median and central interval at
    the calibration's level (one value twice when it was fixed), and whether that interval reached
    the prior's top (``saturated``: the laboratory may lie further from the model than allowed)."""

    prior: str
    median: float
    interval: list[float]
    saturated: bool = False


def discrepancy_record(post, level: float) -> DiscrepancyRecord | None:
    """The record of ``post``'s discrepancy term (None: it had none)."""
    term = post.discrepancy
    if term is None or term.none:
        return None
    if len(term.levels) == 1:
        s = float(term.levels[0])
        return DiscrepancyRecord(f"fixed at {s:g}", s, [s, s])
    tail = (1.0 - level) / 2.0
    prior = f"uniform over {len(term.levels)} levels from {term.levels[0]:g} to {term.levels[-1]:g}"
    weights = post.discrepancy_weights
    saturated = weights is not None and term.saturated(weights, level)
    interval = [post.discrepancy_at(tail), post.discrepancy_at(1.0 - tail)]
    return DiscrepancyRecord(prior, post.discrepancy_at(0.5), interval, saturated)


__all__ = [
    "LEVELS",
    "MODES",
    "SYNTHETIC_HEADER",
    "made_by_poro2d",
    "resolve_mode",
    "Discrepancy",
    "DiscrepancyRecord",
    "discrepancy_record",
    "Levels",
    "check_mode",
    "level_posterior",
    "log_likelihood",
]
