"""One shear test of a calibration: (specimen, normal stress, f_p, mu_r), cached by content.

A unit's folder under ``cache/`` is named by a hash of what decides its result (the
specimen's content, the normal stress, every shear setting with the two frictions), so
a rerun, a second round or another calibration on the same specimens reuses it; inside,
:class:`poro2d.shear.single.DirectShearTest` resumes a test that was killed.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from poro2d.execute.dask_cluster import pin_numba_threads
from poro2d.identity import identity_digest
from poro2d.shear.case import ShearCase
from poro2d.shear.settings import ShearSettings
from poro2d.shear.single import DirectShearTest
from poro2d.shear.specimen_file import Specimen
from poro2d.store import Store

#: what a unit returns besides its identity: the observables a calibration may fit
OBSERVABLES = ("peak", "end")


def unit_key(specimen_digest: str, sigma: float, settings: dict) -> str:
    """The run digest naming a unit's folder (:func:`poro2d.identity.identity_digest`).

    Spaced as these keys were first written, so the folders of earlier calibrations keep
    their names and are reused.
    """
    unit = {"specimen": specimen_digest, "sigma": sigma, "settings": settings}
    return identity_digest(unit, tables={"settings": ShearSettings}, length=20, layout="spaced")


def unit_job(
    specimen: Path, digest: str, sigma: float, base: dict, fp: float, mu_r: float, cache: Path
) -> dict:
    """The job of one unit (a plain dict: it travels to a Dask worker)."""
    settings = dict(base, particle_friction=fp, rolling_friction=mu_r)
    ShearSettings(**settings)  # refused here, on the driver, before any work
    key = unit_key(digest, sigma, settings)
    return {
        "key": key,
        "specimen": str(specimen),
        "digest": digest,
        "sigma": float(sigma),
        "fp": fp,
        "mu_r": mu_r,
        "settings": settings,
        "out": str(cache / key),
    }


def _test(job: dict, threads: int = 1) -> DirectShearTest:
    case = ShearCase(
        Specimen.read(job["specimen"], job["digest"]), job["sigma"], ShearSettings(**job["settings"])
    )
    return DirectShearTest(case, Store(job["out"]), figures=False, threads=threads)


def _row(job: dict, res) -> dict:
    return {
        "key": job["key"],
        "sigma": job["sigma"],
        "fp": job["fp"],
        "mu_r": job["mu_r"],
        "specimen": job["specimen"],
        "peak": float(res["peak_shear_stress_kpa"]),
        "end": float(res["end"]["shear_stress_kpa"]),
        "wall_time_s": float(res["wall_time_s"]),
    }


def stored_row(job: dict) -> dict | None:
    """The unit's row when its folder holds the finished test, else None."""
    res = _test(job).stored()
    return None if res is None else _row(job, res)


def compute_unit(job: dict) -> dict:
    """Run (or finish) one unit, on one numba thread: the task a Dask worker runs."""
    pin_numba_threads()
    return _row(job, _test(job).run())


def unit_curve(job: dict) -> tuple[np.ndarray, np.ndarray] | None:
    """The unit's curve (shear displacement m, shear stress kPa), or None when it has none."""
    path = Path(job["out"]) / "curve.csv"
    if not path.is_file():
        return None
    import pandas as pd

    table = pd.read_csv(path)
    return table["shear_displacement_mm"].to_numpy() * 1e-3, table["shear_stress_kpa"].to_numpy()


__all__ = ["OBSERVABLES", "compute_unit", "stored_row", "unit_curve", "unit_job", "unit_key"]
