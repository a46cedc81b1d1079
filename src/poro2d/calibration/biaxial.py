"""Biaxial laboratory data as a calibration's input: the settings, the targets and the lab record.

``run_calibration(biaxial_lab=...)`` (``poro2d calibrate --biaxial-lab``) fits f_p and mu_r to
laboratory biaxial tests instead of direct shear: one biaxial unit per (specimen, confining
stress, f_p, mu_r) (:mod:`poro2d.calibration.biaxial_units`), and the targets below, read from
the laboratory curves as the units read the simulated ones. The surrogate, the noise and the
posterior are the direct shear calibration's: they work per observable, whatever its unit.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from typing import ClassVar

from poro2d.biaxial.lab import LabTests, read_lab_tests
from poro2d.biaxial.settings import BiaxialSettings
from poro2d.calibration.biaxial_units import BiaxialUnit, end_mean, end_window, peak_ratio
from poro2d.calibration.units import base_of, strain_station, window_mean
from poro2d.errors import InputError
from poro2d.specimen.specimen_set import SpecimenSet
from poro2d.typed_result import TypedResult

#: the ``test`` of a biaxial calibration's ``result.json`` (a direct shear one has none)
BIAXIAL = "biaxial"


@dataclass(eq=False)
class BiaxialLabPoint(TypedResult):
    """One laboratory biaxial test as a calibration's file keeps it."""

    confining_stress_kpa: float
    peak_stress_ratio: float
    last_axial_strain: float
    volumetric_strain: bool


@dataclass(eq=False)
class BiaxialLabRecord(TypedResult):
    """The laboratory biaxial tests of a calibration (its ``lab``): the files and one row per test."""

    source: str
    kind: str
    tests: list[BiaxialLabPoint]

    PARTS: ClassVar[dict[str, type[TypedResult]]] = {"tests": BiaxialLabPoint}

    @classmethod
    def of(cls, lab: LabTests) -> BiaxialLabRecord:
        rows = [
            BiaxialLabPoint(
                s, float(c.stress_ratio.max()), float(c.axial_strain[-1]), c.volumetric_strain is not None
            )
            for s, c in sorted(lab.curves.items())
        ]
        return cls(lab.source, "biaxial curves", rows)


def read_biaxial_lab(value) -> LabTests:
    """The laboratory biaxial tests as given (a :class:`LabTests`), or read from one path or several."""
    if isinstance(value, LabTests):
        return value
    if isinstance(value, str | os.PathLike) or isinstance(value, list | tuple):
        return read_lab_tests(value)
    raise InputError("biaxial_lab", type(value).__name__, "a CSV path, a list of them or a LabTests")


def base_settings(settings: dict | None, calibrated: tuple[str, ...]) -> BiaxialSettings:
    """The biaxial settings of every test (the two frictions apart, which the calibration sets)."""
    return base_of(BiaxialSettings, settings, calibrated)


def biaxial_targets(
    lab: LabTests, base: BiaxialSettings, stations: int = 1
) -> list[tuple[str, float, float]]:
    """(observable, confining stress, laboratory value) fitted: per test the peak and end stress ratios,
    the end volumetric strain when the test has it; with ``stations`` > 1 the readings at
    ``max_strain`` x j / ``stations``, j < ``stations`` (:mod:`poro2d.calibration.biaxial_units`)."""
    for s, c in sorted(lab.curves.items()):
        if c.axial_strain[-1] < base.max_strain:
            raise InputError(
                "settings.max_strain", base.max_strain,
                f"at most {c.axial_strain[-1]:g}, where the lab curve at {s:g} kPa ends",
            )  # fmt: skip
    curves = sorted(lab.curves.items())
    targets = [("peak_ratio", s, peak_ratio(c.axial_strain, c.stress_ratio, base)) for s, c in curves]
    targets += [
        ("end_ratio", s, end_mean(c.axial_strain, c.stress_ratio, base, end_window(base))) for s, c in curves
    ]
    targets += [
        ("end_volumetric", s, end_mean(c.axial_strain, c.volumetric_strain, base, base.smoothing_strain))
        for s, c in curves
        if c.volumetric_strain is not None
    ]
    for j in range(1, stations):
        at = base.max_strain * j / stations
        for s, c in curves:
            w = base.smoothing_strain
            targets.append(
                (strain_station("ratio", at), s, window_mean(c.axial_strain, c.stress_ratio, at, w))
            )
            if c.volumetric_strain is not None:
                value = window_mean(c.axial_strain, c.volumetric_strain, at, w)
                targets.append((strain_station("volumetric", at), s, value))
    return targets


def check_quasi_static(specimens: SpecimenSet, stresses, base: BiaxialSettings) -> None:
    """Refuse, before any test, a strain rate whose inertial number is above ``inertial_limit`` on a
    specimen (and a specimen with a disk outside its box): each specimen is put in its biaxial box
    at the lowest confining stress, where the inertial number is largest, and no step is run."""
    from poro2d.biaxial.case import BiaxialCase
    from poro2d.biaxial.single import BiaxialTest

    for label in specimens:
        BiaxialTest(BiaxialCase.of(specimens.specimen(label), min(stresses), base)).build()


def biaxial_unit(specimens: SpecimenSet, label: str, sigma: float, base: BiaxialSettings, fp: float,
                 mu_r: float) -> BiaxialUnit:  # fmt: skip
    """The biaxial test of specimen ``label`` (of a read set) at sigma_3 = ``sigma`` with (f_p, mu_r)."""
    return BiaxialUnit.at(specimens[label], specimens.digest(label), sigma, base, fp, mu_r)


__all__ = [
    "BIAXIAL",
    "BiaxialLabPoint",
    "BiaxialLabRecord",
    "base_settings",
    "biaxial_targets",
    "biaxial_unit",
    "check_quasi_static",
    "read_biaxial_lab",
]
