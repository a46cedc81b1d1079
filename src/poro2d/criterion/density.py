"""Density-controlled preparation: from a laboratory state to a preparation friction.

With the preparation friction fixed, the criterion of Fig. 3 steers every trial back to
the natural packing of the preparation protocol, whatever laboratory density was asked
for. Here the preparation friction mu_prep is the control variable of the specimen's
density (lubricated compaction packs densest, frictional compaction loosest):

1. **Calibration.** For one grading and box, the criterion runs at a few values of
   mu_prep, several seeds each; its accepted n2D at mu_prep = 0 is the grading's densest
   2D state n2D,min, at the loosest preparation (``mu_loose``) its loosest n2D,max. Both
   are measured in the criterion's end state (self-weight, top plate just touching).
2. **Mapping** (Salot, Gotteland & Villard 2009): the laboratory relative density
   Dr = (e_max - e_Lab) / (e_max - e_min) from void ratios e = n / (1 - n) sets the 2D
   void ratio e2D = e2D,max - Dr (e2D,max - e2D,min).
3. **Inversion.** The mu_prep whose calibrated n2D equals that target is read from a
   monotone fit of the calibration (isotonic regression of the seed means, then linear
   interpolation); the criterion run with it is the check, and its accepted n2D, over
   seeds, is the answer.

This module holds the arithmetic only; running the criterion for the calibration and
the check is the sweep layer's job (:mod:`poro2d.sweep.density`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from poro2d import porosity as P
from poro2d.config import check_number_list
from poro2d.errors import InputError, check_range
from poro2d.json_types import as_json
from poro2d.record import Record

#: the preparation frictions of a calibration, densest first: frictionless preparation gives
#: the grading's densest state (its layers settle: ``settle_drift`` of density mode), 1.0 the
#: loosest this protocol reaches without large pores (jamming density of frictional disks stops
#: falling near mu = 1, Silbert 2010; on the paper grading the interior porosity is about 0.152
#: at 0 and 0.21 at 1.0)
DEFAULT_MUS = (0.0, 0.05, 0.1, 0.2, 0.5, 1.0)
#: the highest preparation friction a calibration may ask for. Frictional disks jam hardly
#: looser above mu = 1 (Silbert 2010): on the paper's box the loosest state's interior solid
#: fraction is 0.792-0.796 at 1.0 and 0.781-0.792 at 5.0 (four seeds from two first trials,
#: each accepted; at 2.0 two of four, docs/criterion.md), its coordination at the frictional
#: floor of 3 from 1.0 on. So 5.0 is the most a study may want for a slightly looser loose end;
#: a value far beyond (1e6) is a typo, not a preparation
MU_PREP_MAX = 5.0


def lab_relative_density(n_lab: float, n_max: float, n_min: float) -> float:
    """Dr of the laboratory state; refuses nLab outside [n_min, n_max] and n_min >= n_max."""
    hi = check_range("n_max", n_max, 0.0, 1.0, lo_open=True, hi_open=True)
    lo = check_range("n_min", n_min, 0.0, 1.0, lo_open=True, hi_open=True)
    if not lo < hi:
        raise InputError("n_min", lo, f"below n_max = {hi}")
    check_range("n_lab", n_lab, lo, hi)
    return float(P.relative_density(n_lab, hi, lo))


def target_porosity_2d(dr: float, n2d_max: float, n2d_min: float) -> float:
    """The 2D porosity at relative density ``dr`` between the grading's 2D extremes.

    e2D = e2D,max - Dr (e2D,max - e2D,min); the mapping is linear in the void ratio, as
    Dr is in the laboratory.
    """
    if not n2d_min < n2d_max:
        raise InputError(
            "calibration", f"n2D,min = {n2d_min:.4f}, n2D,max = {n2d_max:.4f}",
            "a densest state below the loosest one",
            "the loosest preparation packs no looser than the densest: raise mu_loose",
        )  # fmt: skip
    e_hi, e_lo = P.void_ratio(n2d_max), P.void_ratio(n2d_min)
    return P.porosity_from_void_ratio(e_hi - dr * (e_hi - e_lo))


def isotonic_increasing(y, w=None) -> np.ndarray:
    """Least-squares non-decreasing fit of ``y`` (pool adjacent violators), weights ``w``."""
    y = np.asarray(y, dtype=float)
    w = np.ones_like(y) if w is None else np.asarray(w, dtype=float)
    blocks: list[list[float]] = []  # [weighted mean, weight, count]
    for yi, wi in zip(y, w, strict=True):
        blocks.append([yi, wi, 1])
        while len(blocks) > 1 and blocks[-2][0] > blocks[-1][0]:
            m2, w2, c2 = blocks.pop()
            m1, w1, c1 = blocks.pop()
            blocks.append([(m1 * w1 + m2 * w2) / (w1 + w2), w1 + w2, c1 + c2])
    return np.concatenate([np.full(c, m) for m, _, c in blocks])


@dataclass
class Calibration(Record):
    """mu_prep -> accepted n2D of one grading and box, over seeds.

    ``samples[k]`` holds the accepted n2D of every seed at ``mus[k]`` (None where the
    criterion did not converge; such seeds are left out of the mean and counted). Its row
    has the statistics beside the samples: the means, their spread and fit, the failed
    seeds and the frictions dropped.
    """

    ROW = ("mus", "samples", "seeds", "mean", "sd", "fitted", "failed", "dropped")

    mus: list[float]
    samples: list[list[float | None]]
    seeds: list[int] = field(default_factory=list)

    def __post_init__(self) -> None:
        if len(self.mus) < 2 or len(self.mus) != len(self.samples):
            raise InputError("calibration.mus", self.mus, "at least two frictions, one sample list each")
        if any(b <= a for a, b in zip(self.mus, self.mus[1:], strict=False)):
            raise InputError("calibration.mus", self.mus, "strictly increasing preparation frictions")

    # ----------------------------------------------------------- statistics
    def accepted(self, k: int) -> np.ndarray:
        """The accepted n2D of the seeds at ``mus[k]``: the finite samples, in seed order."""
        return np.array([v for v in self.samples[k] if v is not None and math.isfinite(v)], dtype=float)

    @property
    def mean(self) -> np.ndarray:
        return np.array([g.mean() if g.size else math.nan for g in map(self.accepted, range(len(self.mus)))])

    @property
    def sd(self) -> np.ndarray:
        """Sample standard deviation over seeds (0 with one seed)."""
        return np.array(
            [g.std(ddof=1) if g.size > 1 else 0.0 for g in map(self.accepted, range(len(self.mus)))]
        )

    @property
    def failed(self) -> list[int]:
        """Per friction, how many seeds did not give an accepted porosity."""
        return [len(s) - self.accepted(k).size for k, s in enumerate(self.samples)]

    @property
    def dropped(self) -> list[float]:
        """Frictions at which no seed was accepted: they could not be prepared, and are left out."""
        return [mu for k, mu in enumerate(self.mus) if self.accepted(k).size == 0]

    def usable(self) -> Calibration:
        """The calibration of the frictions with at least one accepted seed.

        A friction whose every seed was refused (e.g. frictionless layers that never reach
        equilibrium within the compaction's fallback) gives no sample; the grading's extremes
        are then those of the frictions that could be prepared. Fewer than two is an error.
        """
        keep = [k for k in range(len(self.mus)) if self.accepted(k).size]
        if len(keep) < 2:
            raise InputError(
                "calibration", f"accepted porosities at mu_prep = {[self.mus[k] for k in keep]} only "
                f"(none at {self.dropped})", "at least two frictions accepted by at least one seed",
                "see the calibration's cases for why the criterion did not converge",
            )  # fmt: skip
        return Calibration([self.mus[k] for k in keep], [self.samples[k] for k in keep], self.seeds)

    # --------------------------------------------------------------- checks
    def check(self) -> None:
        """Refuse a calibration that cannot map densities: too few frictions, or not monotone.

        Frictions without an accepted seed are left out (:meth:`usable`). A decrease of the
        seed means with rising friction is tolerated as noise when it is within twice the
        combined standard error of the two means; the fit then pools it.
        """
        cal = self.usable()
        m, s = cal.mean, cal.sd
        n = np.array([max(cal.accepted(k).size, 1) for k in range(len(cal.mus))])
        se = s / np.sqrt(n)
        for k in range(len(cal.mus) - 1):
            drop = m[k] - m[k + 1]
            if drop > 2.0 * math.hypot(se[k], se[k + 1]) and drop > 1e-4:
                raise InputError(
                    "calibration",
                    f"n2D {m[k]:.4f} at mu_prep {cal.mus[k]:g} > {m[k + 1]:.4f} at {cal.mus[k + 1]:g}",
                    "a porosity that does not fall as the preparation friction rises",
                    "more seeds, or frictions further apart",
                )  # fmt: skip
        if not cal.fitted[-1] > cal.fitted[0]:
            raise InputError(
                "calibration", f"n2D from {m[0]:.4f} to {m[-1]:.4f}", "a looser state at the highest "
                "preparation friction than at the lowest", "raise the largest mu_prep (mu_loose)",
            )  # fmt: skip

    @property
    def fitted(self) -> np.ndarray:
        """Non-decreasing fit of the seed means (weights: accepted seeds); NaN where none was."""
        keep = [k for k in range(len(self.mus)) if self.accepted(k).size]
        out = np.full(len(self.mus), math.nan)
        if keep:
            out[keep] = isotonic_increasing(self.mean[keep], [self.accepted(k).size for k in keep])
        return out

    @property
    def n2d_min(self) -> float:
        """The grading's densest 2D porosity: the fit at the lowest friction that was prepared."""
        return float(self.usable().fitted[0])

    @property
    def n2d_max(self) -> float:
        """The grading's loosest 2D porosity: the fit at the highest friction that was prepared."""
        return float(self.usable().fitted[-1])

    def mu_for(self, n2d: float) -> float:
        """The preparation friction whose calibrated n2D is ``n2d`` (monotone interpolation)."""
        cal = self.usable()
        f, mus = cal.fitted, cal.mus
        if n2d < f[0] - 1e-12:
            raise InputError(
                "target n2D", round(n2d, 5), f"[{f[0]:.4f}, {f[-1]:.4f}] (the calibrated range)",
                f"denser than the densest preparation (mu_prep = {mus[0]:g})",
            )  # fmt: skip
        if n2d > f[-1] + 1e-12:
            raise InputError(
                "target n2D", round(n2d, 5), f"[{f[0]:.4f}, {f[-1]:.4f}] (the calibrated range)",
                f"looser than the loosest preparation (mu_prep = {mus[-1]:g}): add a larger mu_prep",
            )  # fmt: skip
        # flat runs of the fit: take the lowest friction that reaches the value
        xs, ys = [mus[0]], [f[0]]
        for mu, v in zip(mus[1:], f[1:], strict=True):
            if v > ys[-1]:
                xs.append(mu)
                ys.append(v)
        if len(xs) == 1:
            return float(xs[0])
        return float(np.interp(n2d, ys, xs))

    # ------------------------------------------------------------------ io
    @classmethod
    def from_dict(cls, d: dict) -> Calibration:
        """The calibration of a row: its samples (the statistics beside them are computed again)."""
        return cls(list(d["mus"]), [list(s) for s in d["samples"]], list(d.get("seeds", [])))

    def to_dict(self) -> dict:
        """Its row as its files hold it (a statistic of no accepted seed as None): the
        ``calibration`` of ``density.json``, ``relation.json`` and ``sand.json``."""
        return as_json(super().to_dict())


@dataclass
class StateTarget(Record):
    """The density-controlled target of one laboratory state; its row is every field."""

    n_lab: float
    relative_density: float
    n2d_target: float
    mu_prep: float


def state_target(n_lab: float, n_max: float, n_min: float, cal: Calibration) -> StateTarget:
    """Dr of the laboratory state, its 2D porosity target and the friction that prepares it."""
    dr = lab_relative_density(n_lab, n_max, n_min)
    cal.check()
    n2d = target_porosity_2d(dr, cal.n2d_max, cal.n2d_min)
    return StateTarget(n_lab, dr, n2d, cal.mu_for(n2d))


def seed_errors(cal: Calibration) -> np.ndarray:
    """The standard error of each friction's mean n' over its seeds (sd / sqrt(n)), for the usable
    frictions of ``cal``. A friction with a single accepted seed has no spread of its own: it takes
    the pooled sd of the frictions with more (NaN when none has two)."""
    cal = cal.usable()
    counts = np.array([cal.accepted(k).size for k in range(len(cal.mus))])
    sd = cal.sd
    many = counts > 1
    dof = int(np.sum(counts[many] - 1))
    pooled = math.sqrt(float(np.sum((counts[many] - 1) * sd[many] ** 2)) / dof) if dof else math.nan
    return np.where(many, sd, pooled) / np.sqrt(counts)


def friction_error(dr: float, cal: Calibration) -> float:
    """The standard error of the friction that prepares relative density ``dr``, from the
    calibration's finite seeds (the delta method).

    mu_prep is read off the seed means twice: the two ends set the 2D target (the Dr mapping
    above) and the frictions around it the inversion (:meth:`Calibration.mu_for`). Each
    friction's mean is moved by its standard error (:func:`seed_errors`) up and down, mu_prep
    found again, and the central differences added in quadrature (the frictions' cases are
    independent packings). NaN when the seeds give no spread.
    """
    return _seed_delta(cal, lambda c: c.mu_for(target_porosity_2d(dr, c.n2d_max, c.n2d_min)))


def target_error(dr: float, cal: Calibration) -> float:
    """The standard error of the 2D target at relative density ``dr`` (the laboratory's Dr mapped
    onto the calibration's extremes, :func:`target_porosity_2d`), from the ends' finite seeds: as
    :func:`friction_error`, the target found again with each friction's mean moved by its
    standard error."""
    return _seed_delta(cal, lambda c: target_porosity_2d(dr, c.n2d_max, c.n2d_min))


def _seed_delta(cal: Calibration, read) -> float:
    """The delta method over the calibration's seed means: ``read`` (a number from a calibration)
    again with each usable friction's mean moved up and down by its standard error, the central
    differences added in quadrature. NaN when the seeds give no spread."""
    cal = cal.usable()
    se = seed_errors(cal)

    def moved(k: int, shift: float) -> float:
        samples = [[v + shift if j == k else v for v in cal.accepted(j)] for j in range(len(cal.mus))]
        return read(Calibration(cal.mus, samples, cal.seeds))

    if not np.all(np.isfinite(se)):
        return math.nan
    parts = [(moved(k, h) - moved(k, -h)) / 2.0 for k, h in enumerate(se) if h > 0.0]
    return float(math.sqrt(sum(p * p for p in parts)))


def check_mus(mus, parameter: str = "density.mu_prep") -> list[float]:
    """Two to 20 preparation frictions in [0, MU_PREP_MAX], strictly increasing (densest first)."""
    return check_number_list(parameter, mus, 0.0, MU_PREP_MAX, min_items=2, max_items=20, increasing=True,
                             what="preparation frictions")  # fmt: skip


__all__ = [
    "DEFAULT_MUS",
    "Calibration",
    "StateTarget",
    "check_mus",
    "friction_error",
    "isotonic_increasing",
    "lab_relative_density",
    "seed_errors",
    "state_target",
    "target_error",
    "target_porosity_2d",
]
