"""``run_shear``: the ``poro2d shear`` command as a Python function.

Everything is checked before the first test starts, and bad input raises
:class:`poro2d.errors.InputError` naming the parameter, as the command does.
"""

from __future__ import annotations

import os
from collections.abc import Iterable

from poro2d.config import dataclass_from_table
from poro2d.errors import InputError, is_number
from poro2d.execute import RunOptions
from poro2d.io_utils import check_output_dir
from poro2d.shear.lab import LabData, read_lab_csv
from poro2d.shear.results import ShearSeriesResult
from poro2d.shear.series import ShearSeries, check_stresses
from poro2d.shear.settings import ShearSettings
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


def run_shear(
    specimen: str | os.PathLike,
    normal_stresses_kpa,
    settings: ShearSettings | dict | None = None,
    *,
    store: Store | None,
    lab: str | os.PathLike | LabData | None = None,
    rate_check: bool = False,
    options: RunOptions = RunOptions(),
    config: dict | None = None,
) -> ShearSeriesResult:
    """Direct shear tests on ``specimen`` at ``normal_stresses_kpa`` and the fit (Fig. 8 is drawn from
    the result: ``draw_shear_series`` (``report/shear_figures.py``)).

    ``specimen``: a checkpoint (.npz) or a criterion output folder holding ``specimen.npz``
    (read once: every test starts from that content). ``normal_stresses_kpa``: a number or
    a list (kPa). ``settings``: a :class:`ShearSettings`, a dict of its fields, or None for
    the defaults. ``store``: where the results are kept (``Store("shear-out")``); a rerun
    with the same inputs skips finished tests and resumes a killed one; None: nothing is kept. ``lab``: a
    laboratory CSV (or :class:`LabData`) to compare with. ``rate_check``: repeat every
    test at half the velocity. ``options``: where the tests run (``workers`` processes, default
    one per test and at most two per core, or a running ``scheduler``) and whether bars show
    (:class:`~poro2d.execute.options.RunOptions`).
    ``config``: recorded in ``result.json`` as it is.

    Returns the :class:`ShearSeriesResult` kept as ``result.json`` (per test ``tests``, the fit
    ``friction_angle_deg``, ``cohesion_kpa``, ``r2``, ...; see docs/shear.md). Tests run in
    spawned processes, which import the calling script: call this under
    ``if __name__ == "__main__":`` in a script. A test that fails to run (consolidation
    without equilibrium) raises RuntimeError once the others have finished.
    """
    if store is not None and not isinstance(store, Store):
        raise InputError("store", type(store).__name__, "a poro2d.store.Store (Store('shear-out')) or None")
    if store is not None:  # a bad folder is refused before the specimen is read
        check_output_dir(store.parameter, store.root)
    value = Specimen.read(specimen)  # a damaged file is refused here, in one line
    stresses = _stresses(normal_stresses_kpa)
    lab_data = _lab(lab)
    shear_settings = _settings(settings)
    if not isinstance(rate_check, bool):
        raise InputError("rate_check", rate_check, "True or False")
    with claimed(store, KIND):
        series = ShearSeries(
            value, stresses, shear_settings, store=store, lab=lab_data, rate_check=rate_check,
            options=options, config=config,
        )  # fmt: skip
        return series.run()


__all__ = ["run_shear"]
