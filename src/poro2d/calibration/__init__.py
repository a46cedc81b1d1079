"""Calibration of particle friction and rolling friction against laboratory direct shear or biaxial tests.

:func:`run_calibration` (``poro2d calibrate``) of a :class:`CalibrationCase`, and :func:`synthetic_lab` and
:func:`synthetic_biaxial_lab`, which make "laboratory" data with poro2d itself at known
parameters (the identifiability check).
"""

from poro2d.calibration.case import CalibrationCase
from poro2d.calibration.run import CalibrationResult, run_calibration
from poro2d.calibration.synthetic import synthetic_biaxial_lab, synthetic_lab

__all__ = [
    "CalibrationCase",
    "CalibrationResult",
    "run_calibration",
    "synthetic_biaxial_lab",
    "synthetic_lab",
]
