"""The replicate specimens a calibration shears: given folders, or the paper preset over seeds.

``--preset paper`` runs the criterion of ``poro2d paper`` on the first seed (its accepted
porosity is the first trial of the others) and replicate criterion runs on the next seeds,
as ``poro2d paper`` does; both are resumable, so a rerun reads the specimens back.
"""

from __future__ import annotations

import os

import numpy as np

from poro2d.calibration.units import CalibrationUnit
from poro2d.errors import InputError, check_int
from poro2d.execute.options import RunOptions
from poro2d.specimen.saved import Specimen
from poro2d.specimen.specimen_set import SpecimenSet
from poro2d.store import Store

#: the most replicate specimens of the preset (each is a criterion run)
MAX_REPLICATES = 20
#: the preset's replicate specimens and first seed unless given
PRESET_REPLICATES = 3
PRESET_SEED = 0


def replicate_unit(specimens: SpecimenSet, label: str, sigma: float, base, fp: float, mu_r: float,
                   **stiffness) -> CalibrationUnit:  # fmt: skip
    """The shear test of specimen ``label`` (of a read set) at ``sigma`` with the frictions (f_p, mu_r)
    on ``base`` (``stiffness``: the disks' ``kn``, ``ks`` where calibrated): its key hashes the
    specimen's content, not where it lies."""
    return CalibrationUnit.at(specimens[label], specimens.digest(label), sigma, base, fp, mu_r, **stiffness)


#: a two-sample Kolmogorov-Smirnov test of two specimens' radii below this p-value says they were
#: drawn from different gradings (replicates of one grading pass it but once in a thousand)
GRADING_P_VALUE = 1e-3


def check_replicates(replicates: SpecimenSet) -> None:
    """Refuse replicates whose differences are not seed scatter, on one line naming the specimen.

    The calibration counts the spread of the replicates at each design point as the seed
    scatter of the laboratory specimen: the same specimen given twice (twins, by content)
    has none, and specimens of other box widths, disk thicknesses or gradings differ by more
    than their seeds, which would be counted as scatter and widen the intervals unseen.
    """
    found = replicates.read()
    seen: dict[str, str] = {}
    for label in found:
        digest = found.digest(label)
        if digest in seen:
            raise InputError(
                "--specimen", str(found[label]), "distinct replicate specimens",
                f"it holds the same state as {found[seen[digest]]} (a twin has no seed scatter)",
            )  # fmt: skip
        seen[digest] = label
    first, *others = list(found)
    ref = _replicate_traits(found.specimen(first))
    for label in others:
        why = _mixed(ref, _replicate_traits(found.specimen(label)))
        if why:
            raise InputError(
                "--specimen", str(found[label]), f"a replicate of {found[first]}",
                f"{why}: their difference is not seed scatter",
            )  # fmt: skip


def _replicate_traits(specimen: Specimen) -> tuple[float, float, np.ndarray]:
    """(box width, disk thickness, radii) of a specimen read: what replicates of one soil share."""
    width = specimen.box()[0]
    return width, float(specimen.meta.get("thickness", 0.0)), specimen.arrays["particles.radius"]


def _mixed(a: tuple[float, float, np.ndarray], b: tuple[float, float, np.ndarray]) -> str | None:
    """Why two specimens are not replicates of one soil in one box, or None."""
    from scipy.stats import ks_2samp

    if not np.isclose(a[0], b[0], rtol=1e-6, atol=0.0):
        return f"its box is {b[0]:g} m wide, not {a[0]:g} m"
    if not np.isclose(a[1], b[1], rtol=1e-6, atol=0.0):
        return f"its disks are {b[1]:g} m thick, not {a[1]:g} m"
    if ks_2samp(a[2], b[2]).pvalue < GRADING_P_VALUE:
        return "its radii are drawn from another grading"
    return None


def check_preset(
    preset: str | None, quick: bool, replicates: int | None, seed: int | None
) -> tuple[int, int]:
    """``--preset`` is ``paper`` (the only one); ``--quick``, ``--replicates`` and ``--seed`` only
    with it: given specimens are sheared as they are, so a count or a seed would be ignored
    without a word. Returns (replicates, seed), the preset's defaults where not given."""
    if preset is not None and preset != "paper":
        raise InputError("--preset", preset, "paper")
    if preset is None:
        for name, value in (("--quick", quick or None), ("--replicates", replicates), ("--seed", seed)):
            if value is not None:
                raise InputError(
                    name, value, "only with --preset paper", "given specimens are sheared as they are"
                )
    replicates = check_int(
        "--replicates", PRESET_REPLICATES if replicates is None else replicates, 1, MAX_REPLICATES
    )
    return replicates, check_int("--seed", PRESET_SEED if seed is None else seed, 0)


def paper_criterion(store: Store, quick: bool, seed: int, threads: int | None, progress: bool):
    """The criterion of the paper's case (``quick``: the small box) on ``seed``, kept in ``store``'s
    ``criterion``, every option checked before a file is written; ``threads``: of the DEM kernels
    (None: at most two)."""
    from poro2d.criterion.config import paper_config
    from poro2d.criterion.protocol import PorosityCriterion

    cfg = paper_config(quick, seed)
    threads = min(os.cpu_count() or 1, 2) if threads is None else threads
    spec, grading, settings, sd = cfg.build(threads=threads)
    kept = store.child("criterion")
    crit = PorosityCriterion(
        spec, grading, settings, seed=sd, store=kept, progress=progress, config=cfg.as_config()
    )
    crit.validate()
    return crit


def preset_specimens(store: Store, *, quick: bool, seed: int, replicates: int, progress: bool) -> SpecimenSet:
    """The paper preset's accepted specimens for ``replicates`` seeds from ``seed``, kept in ``store``.

    The criterion runs once on ``seed`` (its ``criterion``), then on the next seeds from its
    accepted porosity (its ``replicates``); a seed whose criterion does not converge is replaced by
    the next unused one (``ReplicateCase.replacements`` at most).
    """
    from poro2d.criterion.replicates import ReplicateCase, run_replicates

    seed = check_int("--seed", seed, 0)
    crit = paper_criterion(store, quick, seed, None, progress)
    out = store.root
    result = crit.run()
    if not result.converged:
        raise RuntimeError(f"the criterion of seed {seed} did not converge: {result.message}")
    specimens = SpecimenSet.made([(f"seed{seed}", out / "criterion" / "specimen.npz")])
    if replicates > 1:
        extra = tuple(range(seed + 1, seed + replicates))
        options = RunOptions(workers=crit.spec.threads, progress=progress)
        case = ReplicateCase(crit.spec, crit.grading, crit.settings, result.final_porosity, extra)
        specimens += run_replicates(case, store.child("replicates"), options=options).specimens
    return specimens


__all__ = [
    "GRADING_P_VALUE",
    "MAX_REPLICATES",
    "check_preset",
    "check_replicates",
    "paper_criterion",
    "preset_specimens",
    "replicate_unit",
]
