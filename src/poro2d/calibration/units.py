"""One shear test of a calibration: (specimen, normal stress, f_p, mu_r), cached by content.

A unit is a value (:class:`CalibrationUnit`); its store under ``cache/`` is named by a hash
of what decides its result (the specimen's content, the normal stress, every shear setting
with the two frictions), so a rerun, a second round or another calibration on the same
specimens reuses it; inside, :class:`poro2d.shear.single.DirectShearTest` resumes a test
that was killed.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from functools import cached_property
from typing import Any, ClassVar

import numpy as np

from poro2d.errors import InputError
from poro2d.execute.dask_cluster import pin_numba_threads
from poro2d.identity import identity_digest
from poro2d.measure.stiffness import ContactStiffness
from poro2d.shear.case import ShearCase
from poro2d.shear.fit import smooth
from poro2d.shear.record import content_record, folder_stage
from poro2d.shear.settings import ShearSettings
from poro2d.shear.single import DirectShearTest
from poro2d.specimen.saved import Specimen
from poro2d.store import Store
from poro2d.typed_result import with_fields

#: what a unit returns besides its identity: the observables a calibration may fit
OBSERVABLES = ("peak", "end", "dilation")
#: the unit of each observable: the peak and end shear stresses in kPa, the plate's rise in mm
OBSERVABLE_UNITS = {"peak": "kPa", "end": "kPa", "dilation": "mm"}
#: the readings of a curve before its end (``stations``): the shear stress and the plate's rise
#: at a shear displacement, named ``stress_at_5mm``, ``rise_at_5mm``
STATION_UNITS = {"stress": "kPa", "rise": "mm"}
#: the observables of a biaxial test (:mod:`poro2d.calibration.biaxial_units`), all dimensionless:
#: the peak and end stress ratios (sigma_1 - sigma_3) / (sigma_1 + sigma_3) and the volumetric
#: strain at the end (a fraction, compression positive)
BIAXIAL_OBSERVABLES = ("peak_ratio", "end_ratio", "end_volumetric")
#: the unit of a dimensionless observable, as the file's keys name it (``lab_ratio``)
RATIO = "ratio"
#: the readings of a biaxial curve before its end: the stress ratio and the volumetric strain at
#: an axial strain, named ``ratio_at_4pct``, ``volumetric_at_4pct`` (percent of axial strain)
STRAIN_STATION_KINDS = ("ratio", "volumetric")
#: the sub-store of a calibration's store that holds its units, each under its key
CACHE = "cache"


def station(kind: str, displacement_m: float) -> str:
    """The name of a reading of the curve: ``kind`` (:data:`STATION_UNITS`) at ``displacement_m``."""
    return f"{kind}_at_{displacement_m * 1e3:g}mm"


def strain_station(kind: str, axial_strain: float) -> str:
    """The name of a reading of a biaxial curve: ``kind`` (:data:`STRAIN_STATION_KINDS`) at an axial
    strain (a fraction; the name says it in percent)."""
    return f"{kind}_at_{100 * axial_strain:.4g}pct"


def _parse(name: str, kinds, suffix: str, position) -> tuple[str, float] | None:
    """(kind, ``position(x)``) of a reading named ``<kind>_at_<x><suffix>``, or None."""
    kind, sep, rest = name.partition("_at_")
    if not sep or kind not in kinds or not rest.endswith(suffix):
        return None
    return kind, position(float(rest.removesuffix(suffix)))


def parse_station(name: str) -> tuple[str, float] | None:
    """(kind, displacement in m) of a reading's name (:func:`station`), or None for another observable."""
    return _parse(name, STATION_UNITS, "mm", lambda mm: mm * 1e-3)


def parse_strain_station(name: str) -> tuple[str, float] | None:
    """(kind, axial strain as a fraction) of a biaxial reading's name (:func:`strain_station`), or None."""
    return _parse(name, STRAIN_STATION_KINDS, "pct", lambda pct: pct / 100.0)


def observable_unit(name: str) -> str:
    """The unit of the observable ``name``: ``kPa`` or ``mm`` (direct shear), :data:`RATIO` (biaxial:
    dimensionless)."""
    if name in BIAXIAL_OBSERVABLES or parse_strain_station(name) is not None:
        return RATIO
    reading = parse_station(name)
    return OBSERVABLE_UNITS[name] if reading is None else STATION_UNITS[reading[0]]


def window_mean(d: np.ndarray, y: np.ndarray, at: float, window: float) -> float:
    """The mean of ``y`` over the readings of displacement ``d`` (m) within ``window`` before ``at``
    (the value at ``at`` interpolated when no reading lies there): how a curve is read at a station,
    the laboratory's and the simulated one alike."""
    d, y = np.asarray(d, float), np.asarray(y, float)
    inside = (d >= at - window) & (d <= at)
    return float(np.mean(y[inside])) if inside.any() else float(np.interp(at, d, y))


@dataclass(frozen=True)
class CurveReadings:
    """A finished test's curve as the fit reads it at its stations (:func:`window_mean`): ``x`` (the
    shear displacement in m, or the axial strain of a biaxial test), a column per kind of reading
    (``stress`` in kPa and ``rise`` in mm, or ``ratio`` and ``volumetric``) and the window in x.

    Kept in the unit's row, so that readings at any stations come from the cached test without
    running it again."""

    x: np.ndarray
    columns: dict[str, np.ndarray]
    window: float

    def at(self, kind: str, x: float) -> float:
        """The reading of ``kind`` at ``x``."""
        return window_mean(self.x, self.columns[kind], x, self.window)


def unit_key(specimen_digest: str, sigma: float, settings: dict) -> str:
    """The run digest naming a unit's folder (:func:`poro2d.identity.identity_digest`).

    Spaced as these keys were first written, so the folders of earlier calibrations keep
    their names and are reused.
    """
    unit = {"specimen": specimen_digest, "sigma": sigma, "settings": settings}
    return identity_digest(unit, tables={"settings": ShearSettings}, length=20, layout="spaced")


def base_of(kind: type, settings: dict | None, calibrated: tuple[str, ...], **defaults):
    """The settings ``kind`` (shear or biaxial) of every test of a calibration, from the caller's
    table (a command's options), read once here: a setting the calibration sets (``calibrated``) is
    refused, ``defaults`` stand where the table is silent."""
    what = kind.__name__.removesuffix("Settings").lower()
    if not isinstance(settings, dict | None):
        raise InputError("settings", type(settings).__name__, f"a dict of {what} settings or None")
    given = dict(settings or {})
    for name in calibrated:
        if name in given:
            raise InputError(f"settings.{name}", given[name], "not given: it is calibrated")
    from poro2d.config import dataclass_from_table

    return dataclass_from_table(kind, "settings", {**defaults, **given})


@dataclass(frozen=True)
class FrictionUnit:
    """One test of a calibration at a pair (f_p, mu_r), as a value that travels to a Dask worker:
    what every kind of unit (a shear test, a biaxial test) holds and how it is made.

    ``specimen``: the specimen's file; ``digest``: its content (what the cache key hashes,
    not the path); ``sigma``: the test's stress (kPa); ``settings``: every setting of the test,
    the two frictions included.
    """

    specimen: str
    digest: str
    sigma: float
    settings: dict[str, Any]

    #: the kind's settings and case classes (the shear test's or the biaxial test's), and the digest
    #: that names a unit's folder in the cache
    SETTINGS: ClassVar[type]
    CASE: ClassVar[type]
    KEY: ClassVar[Callable[[str, float, dict], str]]

    @classmethod
    def at(cls, specimen, digest: str, sigma: float, base, fp: float, mu_r: float, **stiffness):
        """The unit of ``specimen`` at ``sigma`` with the frictions (f_p, mu_r) on the ``base`` settings
        (``stiffness``: ``kn``, ``ks`` of the disks where calibrated, N/m; else the base's own).

        The settings are checked here, on the driver, before any work; the unit keeps them as
        the table its key hashes (and its worker reads back).
        """
        given = {f"particle_{k}": v for k, v in stiffness.items() if v is not None}
        settings = replace(base, particle_friction=fp, rolling_friction=mu_r, **given)
        return cls(str(specimen), digest, float(sigma), settings.to_dict())

    @property
    def fp(self) -> float:
        return self.settings["particle_friction"]

    @property
    def mu_r(self) -> float:
        return self.settings["rolling_friction"]

    @cached_property
    def key(self) -> str:
        """The unit's identity: the name of its store in the cache (its kind's ``KEY``)."""
        return type(self).KEY(self.digest, self.sigma, self.settings)

    def case(self):
        """The test's case: the specimen read (its content checked against ``digest``), the stress
        and the settings."""
        return self.CASE(Specimen.read(self.specimen, self.digest), self.sigma, self.typed_settings)

    @property
    def typed_settings(self):
        """The settings as their class (the unit keeps them as the table its key hashes)."""
        return self.SETTINGS(**self.settings)

    def store(self, cache: Store | None) -> Store | None:
        """The unit's store in ``cache``, under its key (None: nothing kept)."""
        return None if cache is None else cache.child(self.key)

    def stored(self, cache: Store | None):
        """The finished test's result in ``cache``, or None (a folder not there holds none)."""
        store = self.store(cache)
        return None if store is None or not store.root.is_dir() else self.test(store).stored()

    def stored_row(self, cache: Store | None):
        """The unit's row when its store in ``cache`` holds the finished test, else None."""
        res = self.stored(cache)
        return None if res is None else self.row(res)

    def compute(self, cache: Store | None):
        """Run (or finish) the test: what a Dask worker runs (through :func:`compute_unit`)."""
        return self.row(self.test(self.store(cache)).run())


@dataclass(frozen=True)
class UnitIdentity:
    """The first fields of what a finished unit of any kind gives the fit: its key, its stress (kPa),
    the two frictions and the specimen's file."""

    key: str
    sigma: float
    fp: float
    mu_r: float
    specimen: str


@dataclass(frozen=True)
@with_fields(ContactStiffness, after="box_note")
class UnitRow(UnitIdentity):
    """What a finished unit gives the fit: its observables and its cost.

    ``peak`` and ``end``: shear stresses (kPa); ``dilation``: the plate's rise at the end of
    the test (mm, positive: dilation), smoothed over the peak window as the end stress is (NaN:
    not given, for a row made by hand). ``box_dominated``: the test's verdict, read off its curve
    for a test cached before there was one (:meth:`poro2d.shear.results.ShearTestResult.read`): the
    fit leaves its design point out. ``stiffness_number`` and ``mean_overlap_ratio``: kappa = kn /
    (sigma t) and the mean overlap / d at the peak (None: a test cached before them).
    """

    peak: float
    end: float
    wall_time_s: float
    dilation: float = math.nan
    readings: CurveReadings | None = None
    #: whether the test read its box rather than its material (poro2d.shear.box_dominated), and why
    box_dominated: bool = False
    box_note: str = ""

    def observable(self, name: str) -> float:
        """The value of the observable ``name`` (:data:`OBSERVABLES`, or a reading of the curve,
        :func:`station`; in :func:`observable_unit`)."""
        reading = parse_station(name)
        if reading is None:
            return {"peak": self.peak, "end": self.end, "dilation": self.dilation}[name]
        return math.nan if self.readings is None else self.readings.at(*reading)


@dataclass(frozen=True)
class CalibrationUnit(FrictionUnit):
    """One shear test of a calibration (:class:`FrictionUnit` with the shear settings), read through
    the protocol the runner reads every kind of unit by (the biaxial units keep it too)."""

    #: what the progress display counts (:class:`poro2d.calibration.cluster.UnitRunner`)
    WHAT = "shear tests"
    SETTINGS = ShearSettings
    CASE = ShearCase
    KEY = staticmethod(unit_key)

    def test(self, store: Store | None) -> DirectShearTest:
        return DirectShearTest(self.case(), store, keep_peak=False)

    def check_entry(self, cache: Store | None) -> None:
        """Refuse, on one line naming it, a unit's cache entry that is damaged: what a test resumes from.

        A file where the unit's folder belongs, or a file of the folder that differs from what
        the store wrote (edited, truncated, replaced: :meth:`poro2d.store.Store.check_intact`),
        would fail the test on its worker, and a calibration must not answer without it. So would
        an entry holding work without the record of its test (``test.json`` deleted) or with
        another test's (a folder copied in).
        """
        store = self.store(cache)
        if store is None or not check_files(cache, store, "one shear test of the cache"):
            return
        content = content_record(self.digest, self.sigma, self.typed_settings)
        try:
            folder_stage(store, content, self.specimen).check()
        except InputError:
            raise InputError(
                str(store.root), "work without the record of its test", "a cache entry of this shear test",
                "delete it to have the test computed again",
            ) from None  # fmt: skip

    def curve(self, cache: Store | None) -> tuple[np.ndarray, np.ndarray] | None:
        """The finished test's curve (shear displacement m, shear stress kPa), or None when it has none."""
        res = self.stored(cache)
        if res is None or not res.curve:
            return None
        return res.curve["shear_displacement_mm"] * 1e-3, res.curve["shear_stress_kpa"]

    def row(self, res) -> UnitRow:
        """What the fit reads of the test's result ``res``."""
        window = self.typed_settings.peak_window
        curve = res.curve
        return UnitRow(
            key=self.key,
            sigma=self.sigma,
            fp=self.fp,
            mu_r=self.mu_r,
            specimen=self.specimen,
            peak=float(res.peak_shear_stress_kpa),
            end=float(res.end.shear_stress_kpa),
            wall_time_s=float(res.wall_time_s),
            dilation=end_rise_mm(curve, window),
            readings=CurveReadings(
                np.asarray(curve["shear_displacement_mm"], float) * 1e-3,
                {
                    "stress": np.asarray(curve["shear_stress_kpa"], float),
                    "rise": np.asarray(curve["plate_displacement_mm"], float),
                },
                window,
            ),
            box_dominated=bool(res.box_dominated),
            box_note=res.box_note or "",
            stiffness_number=res.stiffness_number,
            mean_overlap_ratio=res.mean_overlap_ratio_at_peak,
        )


def end_rise_mm(curve, window: float) -> float:
    """The plate's rise (mm) at the end of a test's ``curve``, smoothed over ``window`` (m) as
    its end stress is: read from the curve, so tests cached before dilation was fitted serve it."""
    x = np.asarray(curve["shear_displacement_mm"], float) * 1e-3
    return float(smooth(x, curve["plate_displacement_mm"], window)[-1])


def check_files(cache: Store, store: Store, what: str) -> bool:
    """Refuse a file where the cache or a unit's folder belongs, and a file of the unit's folder that
    differs from what the store wrote; whether the folder exists (then its record is checked)."""
    for folder, name in ((cache.root, "the calibration's cache"), (store.root, what)):
        if folder.exists() and not folder.is_dir():
            raise InputError(
                str(folder), "a file", f"a folder ({name})", "delete it to have the tests computed again"
            )
    if not store.root.exists():
        return False
    for name in store.names():
        if store.has(name):
            store.check_intact(name)
    return True


def compute_unit(unit, cache: Store | None):
    """Run (or finish) one unit of any kind (its ``compute``), on one numba thread: the task a Dask
    worker runs."""
    pin_numba_threads()
    return unit.compute(cache)


__all__ = [
    "BIAXIAL_OBSERVABLES",
    "CACHE",
    "RATIO",
    "STRAIN_STATION_KINDS",
    "parse_strain_station",
    "strain_station",
    "OBSERVABLES",
    "OBSERVABLE_UNITS",
    "STATION_UNITS",
    "CurveReadings",
    "observable_unit",
    "parse_station",
    "station",
    "window_mean",
    "CalibrationUnit",
    "FrictionUnit",
    "UnitIdentity",
    "UnitRow",
    "base_of",
    "check_files",
    "compute_unit",
    "end_rise_mm",
    "unit_key",
]
