"""The replicate specimens a calibration shears: given folders, or the paper preset over seeds.

``--preset paper`` runs the criterion of ``poro2d paper`` on the first seed (its accepted
porosity is the first trial of the others) and replicate criterion runs on the next seeds,
as ``poro2d paper`` does; both are resumable, so a rerun reads the specimens back.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from poro2d.calibration.units import CalibrationUnit
from poro2d.errors import InputError, check_int
from poro2d.shear.specimen_file import Specimen, resolve_specimen
from poro2d.store import Store

#: the most replicate specimens of the preset (each is a criterion run)
MAX_REPLICATES = 20


def given_specimens(paths: list[str | os.PathLike]) -> dict[str, Path]:
    """Specimens by label (their folder or file name; made unique) from ``--specimen`` paths."""
    if not paths:
        raise InputError("--specimen", "none", "at least one specimen (or --preset paper)")
    found: dict[str, Path] = {}
    for given in paths:
        path = resolve_specimen(given)
        Store(path.parent).read_state(path.name)  # a damaged file is refused here, in one line
        label = path.parent.name if path.name == "specimen.npz" else path.stem
        label = label or "specimen"
        unique, k = label, 1
        while unique in found:
            k += 1
            unique = f"{label}-{k}"
        found[unique] = path
    return found


@dataclass(frozen=True)
class Replicates:
    """The replicate specimens a calibration shears: each one's file by label, and the digest of
    its content (what a unit's key hashes: a specimen moved to another folder is the same one)."""

    paths: dict[str, Path]
    digests: dict[str, str]

    @classmethod
    def read(cls, paths: dict[str, Path]) -> Replicates:
        """The replicates of the files ``paths`` (by label), each file's content hashed once.

        Each file is read whole through its folder's store: a specimen changed since it was
        written (a preset's, kept in the output folder) or unreadable is refused on one line
        naming it, before any test.
        """
        from poro2d.dem.checkpoint import content_digest

        digests = {}
        for label, path in paths.items():
            meta, arrays = Store(path.parent).read_state(path.name)
            digests[label] = content_digest(meta, arrays)
        return cls(dict(paths), digests)

    def __len__(self) -> int:
        return len(self.paths)

    def unit(self, label: str, sigma: float, base, fp: float, mu_r: float) -> CalibrationUnit:
        """The shear test of specimen ``label`` at ``sigma`` with the frictions (f_p, mu_r) on ``base``."""
        return CalibrationUnit.at(self.paths[label], self.digests[label], sigma, base, fp, mu_r)


#: a two-sample Kolmogorov-Smirnov test of two specimens' radii below this p-value says they were
#: drawn from different gradings (replicates of one grading pass it but once in a thousand)
GRADING_P_VALUE = 1e-3


def check_replicates(replicates: Replicates) -> None:
    """Refuse replicates whose differences are not seed scatter, on one line naming the specimen.

    The calibration counts the spread of the replicates at each design point as the seed
    scatter of the laboratory specimen: the same specimen given twice (twins, by content)
    has none, and specimens of other box widths, disk thicknesses or gradings differ by more
    than their seeds, which would be counted as scatter and widen the intervals unseen.
    """
    found, digests = replicates.paths, replicates.digests
    seen: dict[str, str] = {}
    for label, digest in digests.items():
        if digest in seen:
            raise InputError(
                "--specimen", str(found[label]), "distinct replicate specimens",
                f"it holds the same state as {found[seen[digest]]} (a twin has no seed scatter)",
            )  # fmt: skip
        seen[digest] = label
    first, *others = list(found)
    ref = _replicate_traits(found[first], digests[first])
    for label in others:
        traits = _replicate_traits(found[label], digests[label])
        why = _mixed(ref, traits)
        if why:
            raise InputError(
                "--specimen", str(found[label]), f"a replicate of {found[first]}",
                f"{why}: their difference is not seed scatter",
            )  # fmt: skip


def _replicate_traits(path: Path, digest: str) -> tuple[float, float, np.ndarray]:
    """(box width, disk thickness, radii) of a specimen: what replicates of one soil share."""
    specimen = Specimen.read(path, digest)
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


def check_preset(preset: str | None, quick: bool, replicates: int) -> None:
    """``--preset`` is ``paper`` (the only one), ``--quick`` only with it, replicates in range."""
    if preset is not None and preset != "paper":
        raise InputError("--preset", preset, "paper")
    if quick and preset is None:
        raise InputError("--quick", True, "only with --preset paper")
    check_int("--replicates", replicates, 1, MAX_REPLICATES)


def preset_specimens(
    store: Store, *, quick: bool, seed: int, replicates: int, progress: bool
) -> dict[str, Path]:
    """The paper preset's accepted specimens for ``replicates`` seeds from ``seed``, kept in ``store``.

    The criterion runs once on ``seed`` (its ``criterion``), then on the next seeds from its
    accepted porosity (its ``replicates``); seeds whose criterion does not converge are left out.
    """
    from poro2d.criterion.config import paper_config
    from poro2d.criterion.protocol import PorosityCriterion
    from poro2d.criterion.replicates import run_replicates

    seed = check_int("--seed", seed, 0)
    cfg = paper_config(quick, seed)
    spec, grading, settings, sd = cfg.build(threads=min(os.cpu_count() or 1, 2))
    out = store.root
    crit = PorosityCriterion(
        spec,
        grading,
        settings,
        seed=sd,
        store=store.child("criterion"),
        progress=progress,
        config=cfg.as_config(),
    )
    crit.validate()
    result = crit.run()
    if not result.converged:
        raise RuntimeError(f"the criterion of seed {seed} did not converge: {result.message}")
    specimens = {f"seed{seed}": out / "criterion" / "specimen.npz"}
    if replicates > 1:
        extra = list(range(seed + 1, seed + replicates))
        more = run_replicates(
            spec,
            grading,
            settings,
            result.final_porosity,
            extra,
            store.child("replicates"),
            processes=spec.threads,
            progress=progress,
        )
        specimens.update(more.specimens)
    return specimens


__all__ = [
    "GRADING_P_VALUE",
    "MAX_REPLICATES",
    "Replicates",
    "check_preset",
    "check_replicates",
    "given_specimens",
    "preset_specimens",
]
