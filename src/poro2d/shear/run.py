"""``run_shear``: the ``poro2d shear`` command as a Python function, of a :class:`ShearSeriesCase`.

Everything is checked when the case is made, before the first test starts, and bad input raises
:class:`poro2d.errors.InputError` naming the parameter, as the command does.
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from dataclasses import dataclass
from functools import partial
from typing import Any

from poro2d.config import dataclass_from_table
from poro2d.errors import InputError, is_number
from poro2d.execute import RunOptions
from poro2d.io_utils import check_output_dir
from poro2d.shear.lab import LabData, read_lab_csv
from poro2d.shear.results import ShearSeriesResult
from poro2d.shear.series import ShearSeries, check_stresses
from poro2d.shear.settings import ShearSettings, half_velocity
from poro2d.specimen.saved import Specimen
from poro2d.store import Store, claimed

#: the kind of run an output folder of this command belongs to (poro2d.locks.KIND_SIGNS)
KIND = "shear"


def _stresses(value) -> list[float]:
    """A number or an iterable of numbers (kPa), each > 0, all different."""
    if is_number(value):
        value = [value]
    if isinstance(value, str | bytes | dict) or not isinstance(value, Iterable):
        raise InputError("normal_stresses_kpa", value, "a number or a list of numbers in kPa")
    return check_stresses(list(value))


def _settings(value) -> ShearSettings:
    """ShearSettings as given, from a dict of its fields (unknown keys refused), or the defaults."""
    if value is None:
        return ShearSettings()
    if isinstance(value, ShearSettings):
        return value
    if isinstance(value, dict):
        return dataclass_from_table(ShearSettings, "settings", value)
    raise InputError("settings", type(value).__name__, "a ShearSettings, a dict of its fields or None")


def _lab(value) -> LabData | None:
    """Laboratory data as given, read from a CSV path, or None."""
    if value is None or isinstance(value, LabData):
        return value
    if isinstance(value, str | os.PathLike):
        return read_lab_csv(value)
    raise InputError("lab", type(value).__name__, "a laboratory CSV path, a LabData or None")


@dataclass(frozen=True, eq=False)
class ShearSeriesCase:
    """A series of direct shear tests, checked when made: what :func:`run_shear` computes.

    ``specimen``: a :class:`~poro2d.specimen.saved.Specimen`, or a checkpoint (.npz) or criterion
    output folder holding ``specimen.npz``, read here (every test starts from that content).
    ``normal_stresses_kpa``: a number or a list (kPa). ``settings``: a :class:`ShearSettings`, a
    dict of its fields, or None for the defaults. ``lab``: a laboratory CSV (or :class:`LabData`)
    to compare with. ``rate_check``: repeat every test at half the velocity. ``config``: recorded
    in ``result.json`` as it is.
    """

    specimen: Specimen | str | os.PathLike
    normal_stresses_kpa: Any
    settings: ShearSettings | dict | None = None
    lab: LabData | str | os.PathLike | None = None
    rate_check: bool = False
    config: dict | None = None

    def __post_init__(self) -> None:
        set_field = partial(object.__setattr__, self)
        set_field("specimen", Specimen.of(self.specimen))  # a damaged file is refused here, in one line
        set_field("normal_stresses_kpa", tuple(_stresses(self.normal_stresses_kpa)))
        set_field("lab", _lab(self.lab))
        set_field("settings", _settings(self.settings))
        if not isinstance(self.rate_check, bool):
            raise InputError("rate_check", self.rate_check, "True or False")
        if self.rate_check:  # its rerun at half the velocity is refused before the folder is claimed
            half_velocity(self.settings.velocity)


def run_shear(
    case: ShearSeriesCase, store: Store | None = None, *, options: RunOptions = RunOptions()
) -> ShearSeriesResult:
    """Direct shear tests of ``case`` and the fit (Fig. 8 is drawn from the result:
    ``draw_shear_series`` (``report/shear_figures.py``)).

    ``store``: where the results are kept (``Store("shear-out")``); a rerun with the same case skips
    finished tests and resumes a killed one; None: nothing is kept. ``options``: where the tests run
    (``workers`` processes, default one per test and at most two per core, or a running
    ``scheduler``) and whether bars show (:class:`~poro2d.execute.options.RunOptions`).

    Returns the :class:`ShearSeriesResult` kept as ``result.json`` (per test ``tests``, the fit
    ``friction_angle_deg``, ``cohesion_kpa``, ``r2``, ...; see docs/shear.md). Tests run in
    spawned processes, which import the calling script: call this under
    ``if __name__ == "__main__":`` in a script. A test that fails to run (consolidation
    without equilibrium) raises RuntimeError once the others have finished.
    """
    if not isinstance(case, ShearSeriesCase):
        raise InputError("case", type(case).__name__, "a ShearSeriesCase(specimen, normal_stresses_kpa, ...)")
    if store is not None and not isinstance(store, Store):
        raise InputError("store", type(store).__name__, "a poro2d.store.Store (Store('shear-out')) or None")
    if store is not None:
        check_output_dir(store.parameter, store.root)
    with claimed(store, KIND):
        series = ShearSeries(
            case.specimen, list(case.normal_stresses_kpa), case.settings, store=store, lab=case.lab,
            rate_check=case.rate_check, options=options, config=case.config,
        )  # fmt: skip
        return series.run()


__all__ = ["ShearSeriesCase", "run_shear"]
