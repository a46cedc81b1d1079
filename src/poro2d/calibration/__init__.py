"""Calibration of particle friction and rolling friction against laboratory direct shear.

:func:`run_calibration` (``poro2d calibrate``) and :func:`synthetic_lab`, which makes
"laboratory" data with poro2d itself at known parameters (the identifiability check).
"""

from poro2d.calibration.run import CalibrationResult, run_calibration
from poro2d.calibration.synthetic import synthetic_lab

__all__ = ["CalibrationResult", "run_calibration", "synthetic_lab"]
