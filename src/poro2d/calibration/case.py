"""What a calibration computes from, as one frozen value checked when made (:class:`CalibrationCase`).

:meth:`CalibrationCase.of` reads the laboratory data and the given specimens and checks every
choice (ranges, design, noise, stations, settings) before any test: ``poro2d calibrate`` and
:func:`poro2d.calibration.run.run_calibration` then only run it. A bad value raises
:class:`~poro2d.errors.InputError` naming its option.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from poro2d.biaxial.lab import LabTests
from poro2d.biaxial.settings import BiaxialSettings
from poro2d.calibration import model
from poro2d.calibration.biaxial import base_settings, biaxial_targets, biaxial_unit, read_biaxial_lab
from poro2d.calibration.discrepancy import resolve_mode
from poro2d.calibration.evaluations import PARAMETER_KEYS
from poro2d.calibration.identifiable import check_enough_lab_values
from poro2d.calibration.lab_repeats import LabRepeats, mean_targets
from poro2d.calibration.specimens import check_preset, replicate_unit
from poro2d.calibration.units import base_of, station, window_mean
from poro2d.errors import InputError, check_int, check_range, is_number
from poro2d.paper_data import QUICK_SHEAR
from poro2d.shear.lab import LabData
from poro2d.shear.series import check_stresses
from poro2d.shear.settings import MAX_FRICTION, MAX_ROLLING_FRICTION, PARTICLE_STIFFNESS_RANGE, ShearSettings
from poro2d.specimen.specimen_set import SpecimenSet

DEFAULT_FP_RANGE = (0.3, 3.0)
DEFAULT_MU_R_RANGE = (0.0, 0.5)
#: most design points of a round (each is replicates x stresses shear tests)
MAX_POINTS = 500
#: most stations along a curve (``stations``): each adds one or two observables per normal stress,
#: and the replicates must estimate the noise covariance of them all
MAX_STATIONS = 10
#: the degrees of freedom left to the surrogate's residual beyond its coefficients: with fewer,
#: the quadratic passes (nearly) through every replicate mean and its misfit, one of the noise
#: terms, cannot be estimated (six points fit its six coefficients exactly: a residual of zero)
RESIDUAL_DOF = 3
#: the fewest design points of the first round (the quadratic surrogate has 6 coefficients)
MIN_POINTS = model.N_COEFFICIENTS + RESIDUAL_DOF
#: the settings calibrated here: given ones would be overridden, so they are refused
CALIBRATED = ("particle_friction", "rolling_friction")
#: the names of the stiffness options, per axis
STIFFNESS_OPTIONS = {"kn": "--kn-range", "ks": "--ks-range"}

Target = tuple[str, float, float]


def min_points(d: int) -> int:
    """The fewest design points of the first round in ``d`` parameters: the quadratic's
    (d + 1)(d + 2) / 2 coefficients and :data:`RESIDUAL_DOF` more (9, 13 and 18 for 2, 3, 4)."""
    return model.n_coefficients(d) + RESIDUAL_DOF


@dataclass(frozen=True, eq=False)
class CalibrationCase:
    """A calibration's inputs, checked against each other (made by :meth:`of`).

    ``repeats``: the laboratory data, direct shear series (:class:`LabRepeats`) or biaxial tests
    (:class:`LabTests`); ``specimens``: the given replicates, read, or None with ``preset``
    (``quick``, ``replicates`` seeds from ``seed``: made in the run's store); ``ranges`` and the
    design (``points``, ``refine``, ``design_seed``); ``base``: every test's settings (frictions
    apart); ``targets``: (observable, stress, laboratory value) fitted, ``lab_series`` every
    repeat's values (None: biaxial); ``config``: recorded in ``result.json`` as it is.
    """

    repeats: LabRepeats | LabTests
    specimens: SpecimenSet | None
    ranges: model.Ranges
    base: ShearSettings | BiaxialSettings
    targets: list[Target]
    lab_series: np.ndarray | None = field(default=None, repr=False)
    preset: str | None = None
    quick: bool = False
    replicates: int = 3
    seed: int = 0
    points: int = 12
    refine: int = 6
    design_seed: int = 0
    lab_error: float = 0.0
    level: float = 0.95
    stations: int = 1
    discrepancy: str | float = "none"
    keep_box_dominated: bool = False
    config: dict[str, Any] = field(default_factory=dict)

    @classmethod
    def of(
        cls,
        lab: str | os.PathLike | LabData | LabTests | list | None = None,
        specimens: list[str | os.PathLike] | None = None,
        *,
        biaxial_lab: str | os.PathLike | list | LabTests | None = None,
        preset: str | None = None,
        quick: bool = False,
        replicates: int | None = None,
        seed: int | None = None,
        fp_range=DEFAULT_FP_RANGE,
        mu_r_range=DEFAULT_MU_R_RANGE,
        kn_range=None,
        ks_range=None,
        points: int = 12,
        refine: int = 6,
        design_seed: int = 0,
        lab_error: float = 0.0,
        level: float = 0.95,
        stations: int = 1,
        settings: dict | None = None,
        config: dict | None = None,
        keep_box_dominated: bool = False,
        discrepancy: str | float = "auto",
    ) -> CalibrationCase:
        """The case of the given options, every one checked and every file read here, so that a bad
        one is refused before any test.

        ``specimens``: checkpoints or criterion folders, or ``preset="paper"`` (``quick``: the small box)
        with ``replicates`` seeds (3) from ``seed`` (0), both refused without the preset. ``fp_range``,
        ``mu_r_range``: the search ranges.
        ``kn_range``, ``ks_range``: (low, high) N/m to calibrate the disks' normal and shear stiffness
        too, searched in their logarithm (None: the specimen's, or the settings'); with either, the
        posterior is sampled with emcee (docs/calibration.md). ``points``: the space-filling design's
        size; ``refine``: points of the second round, drawn from the posterior (0: none).
        ``lab_error``: the laboratory's own error as a fraction of each value, added to the seed
        scatter. ``level``: of the credible intervals. ``stations``: with laboratory curves, each curve
        is also read (shear stress, and the plate's rise when given) at ``stations`` - 1 evenly spaced
        displacements before its end (1: peaks, end values and dilation only). ``settings``: shear
        settings of every test (the quick preset's ``max_displacement`` 4 mm by default).

        ``lab`` may be a list: repeats of one laboratory programme (the same normal stresses and
        readings, new specimens). Their mean values are fitted and the laboratory's share of the noise
        is one simulated specimen's scatter over their number, scaled up when the repeats scatter more
        (:mod:`poro2d.calibration.lab_repeats`).

        ``biaxial_lab`` instead of ``lab``: laboratory biaxial tests (one CSV or several, rows named by
        ``confining_stress_kpa``; or a :class:`poro2d.biaxial.lab.LabTests`, which ``lab`` also takes):
        every unit is then a biaxial test at a laboratory confining stress, the targets its stress
        ratios and volumetric strain (:mod:`poro2d.calibration.biaxial`), and ``settings`` are biaxial
        settings (``max_strain`` 0.2 by default).

        A design point any of whose direct shear tests is box-dominated (:mod:`poro2d.shear.box_dominated`:
        its shear plane carries outside 0.7-1.3 times the plate's load at the peak, or its stress never
        peaked) is left out of the fit, and the result says how many were (``box_dominated``); too few
        left for the surrogate is no answer. ``keep_box_dominated``: fit them all the same (a box where
        every test is box-dominated: the frictions then describe the box).

        ``discrepancy``: the model-discrepancy term (:mod:`poro2d.calibration.discrepancy`): ``estimate``
        (integrated over its unknown size), ``none`` (the noise covariance alone), ``auto`` (``none`` for
        laboratory files poro2d wrote itself, else ``estimate``) or a fixed size in each observable's
        noise sd.
        """
        repeats = read_lab(lab, biaxial_lab)
        biaxial = isinstance(repeats, LabTests)
        lab_data = repeats if biaxial else repeats.first
        if not biaxial:
            check_stresses(lab_data.normal_stresses())
        replicates, seed = check_preset(preset, quick, replicates, seed)
        if preset is not None and specimens:
            raise InputError("--specimen", ", ".join(map(str, specimens)), "nothing with --preset")
        # every given specimen accepted and read whole (a damaged file refused on one line) before any work
        given = SpecimenSet.named(specimens or []).read() if preset is None else None
        ranges = model.Ranges(
            check_range_pair("--fp-range", fp_range, 0.0, MAX_FRICTION, lo_open=True),
            check_range_pair("--mu-r-range", mu_r_range, 0.0, MAX_ROLLING_FRICTION),
            **stiffness_ranges(kn_range, ks_range, biaxial),
        )
        points = check_points(points, ranges.dim)
        refine = check_int("--refine", refine, 0, MAX_POINTS)
        design_seed = check_int("--design-seed", design_seed, 0)
        check_range("--lab-error", lab_error, 0.0, 1.0)
        check_range("--level", level, 0.0, 1.0, lo_open=True, hi_open=True)
        discrepancy = resolve_mode(discrepancy, biaxial_lab if lab is None else lab)
        if not isinstance(keep_box_dominated, bool):
            raise InputError("--keep-box-dominated", keep_box_dominated, "true or false")
        if settings is None and quick and not biaxial:
            settings = dict(QUICK_SHEAR)
        calibrated = CALIBRATED + tuple(PARAMETER_KEYS[a] for a in ranges.axes[2:])
        base = base_settings(settings, CALIBRATED) if biaxial else shear_base_settings(settings, calibrated)
        stations = check_int("--stations", stations, 1, MAX_STATIONS)
        if stations > 1 and not biaxial and not lab_data.curves:
            why = "readings along a curve need the lab curves"
            raise InputError("--stations", stations, "1 with a peaks file", why)
        lab_series = None  # every laboratory series' values (series x targets), shear only
        if biaxial:
            targets = biaxial_targets(lab_data, base, stations)
        else:
            targets, lab_series = mean_targets([lab_targets(x, base, stations) for x in repeats.series])
        check_enough_lab_values(lab_data.source, targets, ranges.dim)
        check_noise_dof(points, len(given) if given is not None else replicates, len(targets))
        return cls(
            repeats, given, ranges, base, targets, lab_series, preset, quick, replicates, seed,
            points, refine, design_seed, lab_error, level, stations, discrepancy, keep_box_dominated,
            dict(config or {}),
        )  # fmt: skip

    @property
    def biaxial(self) -> bool:
        """Whether the laboratory tests are biaxial ones (the stress of each target is sigma_3)."""
        return isinstance(self.repeats, LabTests)

    @property
    def lab(self) -> LabData | LabTests:
        """The laboratory data the targets' stresses and the files' records come from."""
        return self.repeats if self.biaxial else self.repeats.first

    @property
    def stresses(self) -> list[float]:
        """The laboratory's normal (or confining) stresses, kPa: every design point's tests."""
        return self.lab.confining_stresses() if self.biaxial else self.lab.normal_stresses()

    @property
    def make(self):
        """The unit of one test: a biaxial one, or a direct shear test of a replicate."""
        return biaxial_unit if self.biaxial else replicate_unit


def check_points(points, dim: int) -> int:
    """The first round's design points: enough for the surrogate of ``dim`` parameters and its residual."""
    fewest = min_points(dim)
    try:
        return check_int("--points", points, fewest, MAX_POINTS)
    except InputError:
        raise InputError(
            "--points", points, f"an integer in [{fewest}, {MAX_POINTS}]",
            f"the surrogate's {model.n_coefficients(dim)} coefficients and {RESIDUAL_DOF} degrees"
            " of freedom to estimate its residual",
        ) from None  # fmt: skip


def check_range_pair(name: str, value, lo: float, hi: float, lo_open: bool = False) -> tuple[float, float]:
    """A (low, high) pair inside [lo, hi] with low < high."""
    if isinstance(value, str | bytes) or not hasattr(value, "__len__") or len(value) != 2:
        raise InputError(name, value, f"two numbers LOW,HIGH in [{lo}, {hi}]")
    a, b = value
    for v in (a, b):
        if not is_number(v):
            raise InputError(name, value, f"two numbers LOW,HIGH in [{lo}, {hi}]")
        check_range(name, float(v), lo, hi, lo_open=lo_open)
    if not float(a) < float(b):
        raise InputError(name, value, "LOW < HIGH")
    return float(a), float(b)


def shear_base_settings(settings: dict | None, calibrated: tuple[str, ...] = CALIBRATED) -> ShearSettings:
    """The shear settings of every test (frictions apart); ``stop_after_peak`` 0 by default so
    that every test ends at ``max_displacement``, where the end stress is compared.

    ``settings``: the caller's table of shear settings (a command's options), read once here;
    ``calibrated``: the settings the calibration sets (a disk stiffness given is kept when it is
    not calibrated)."""
    return base_of(ShearSettings, settings, calibrated, stop_after_peak=0.0)


def lab_targets(lab: LabData, base: ShearSettings, stations: int = 1) -> list[Target]:
    """(observable, normal stress, laboratory value) fitted: every peak; with curves the end stress;
    with the plate's vertical displacement too the dilation (mm); with ``stations`` > 1 the
    readings of each curve at ``stations`` - 1 evenly spaced displacements before the end.

    The end values of a laboratory curve are its means over the last peak window before the
    tests' ``max_displacement`` (the simulated end values are smoothed over the same window);
    a reading is its mean over the peak window before its station, on both sides
    (:func:`poro2d.calibration.units.window_mean`).
    """
    targets = [("peak", s, lab.peaks[s]) for s in lab.normal_stresses()]
    for s in lab.normal_stresses() if lab.curves else []:
        d, t = lab.curves[s]
        if d[-1] < base.max_displacement:
            raise InputError(
                "settings.max_displacement",
                base.max_displacement,
                f"at most {d[-1]:g} m, where the lab curve at {s:g} kPa ends",
            )
        targets.append(("end", s, end_mean(d, t, base)))
    for s in lab.normal_stresses() if lab.vertical else []:
        targets.append(("dilation", s, 1e3 * end_mean(lab.curves[s][0], lab.vertical[s], base)))
    return targets + station_targets(lab, base, stations)


def station_targets(lab: LabData, base: ShearSettings, stations: int) -> list[Target]:
    """The readings of the laboratory curves before their end: the shear stress (kPa) and, when the
    file has it, the plate's rise (mm) at ``max_displacement`` x j / ``stations``, j < ``stations``."""
    targets = []
    for j in range(1, stations):
        at = base.max_displacement * j / stations
        for s in lab.normal_stresses():
            d, t = lab.curves[s]
            targets.append((station("stress", at), s, window_mean(d, t, at, base.peak_window)))
            if lab.vertical:
                rise = window_mean(d, lab.vertical[s], at, base.peak_window)
                targets.append((station("rise", at), s, 1e3 * rise))
    return targets


def end_mean(d: np.ndarray, y: np.ndarray, base: ShearSettings) -> float:
    """The mean of ``y`` over the readings within the last peak window before ``max_displacement``
    (the value at ``max_displacement`` interpolated when no reading lies in that window)."""
    return window_mean(d, y, base.max_displacement, base.peak_window)


def stiffness_ranges(kn_range, ks_range, biaxial: bool) -> dict[str, tuple[float, float]]:
    """The search ranges of the disks' stiffnesses that are calibrated (N/m), checked; refused
    with biaxial laboratory tests, whose settings do not replace the disks' stiffness."""
    out = {}
    for axis, value in {"kn": kn_range, "ks": ks_range}.items():
        if value is None:
            continue
        option = STIFFNESS_OPTIONS[axis]
        if biaxial:
            raise InputError(
                option, value, "not given with --biaxial-lab", "kn and ks are calibrated on direct shear only"
            )
        out[axis] = check_range_pair(option, value, *PARTICLE_STIFFNESS_RANGE)
    return out


def read_lab(lab, biaxial_lab) -> LabRepeats | LabTests:
    """The laboratory data: direct shear (``lab``: one series or repeats) or biaxial tests
    (``biaxial_lab``), exactly one."""
    if isinstance(lab, LabTests) and biaxial_lab is None:
        lab, biaxial_lab = None, lab
    if (lab is None) == (biaxial_lab is None):
        given = "neither" if lab is None else "both"
        raise InputError(
            "--lab",
            given,
            "exactly one of --lab (direct shear peaks or curves) and --biaxial-lab (biaxial curves)",
        )
    if biaxial_lab is not None:
        return read_biaxial_lab(biaxial_lab)
    return LabRepeats.of(lab)


def check_noise_dof(points: int, replicates: int, observables: int) -> None:
    """Refuse, before any test, a design whose replicates cannot estimate the noise of its
    observables: the covariance of ``observables`` values needs points x (replicates - 1) >
    observables + 1 degrees of freedom (:func:`poro2d.calibration.model.precision_factor`).
    One specimen is let through: its intervals are reported as unknown."""
    if replicates < 2 or model.precision_factor(points * (replicates - 1), observables) > 0:
        return
    need = -(-(observables + 2) // (replicates - 1))
    raise InputError(
        "--points", points, f"at least {need} for {observables} observables on {replicates} replicates",
        "the noise covariance needs points x (replicates - 1) > observables + 1; or give fewer --stations",
    )  # fmt: skip


__all__ = [
    "CALIBRATED",
    "DEFAULT_FP_RANGE",
    "DEFAULT_MU_R_RANGE",
    "MIN_POINTS",
    "CalibrationCase",
    "check_noise_dof",
    "lab_targets",
    "min_points",
    "shear_base_settings",
]
