"""Biaxial tests (the 2D triaxial test): a specimen consolidated to sigma_3 by servoed walls,
then axial strain at constant sigma_3; peak and critical-state friction angles, dilatancy."""

from poro2d.biaxial.case import BiaxialCase
from poro2d.biaxial.curve import BiaxialCurve
from poro2d.biaxial.quick import QuickSpecimen
from poro2d.biaxial.results import BiaxialResult, BiaxialSeriesResult, BiaxialTestResult
from poro2d.biaxial.run import run_biaxial
from poro2d.biaxial.series import BiaxialSeriesCase, run_biaxial_series
from poro2d.biaxial.settings import BiaxialSettings, inertial_number
from poro2d.biaxial.single import BiaxialTest

__all__ = [
    "BiaxialCase", "BiaxialCurve", "BiaxialResult", "BiaxialSeriesCase", "BiaxialSeriesResult",
    "BiaxialSettings", "BiaxialTest", "BiaxialTestResult", "QuickSpecimen", "inertial_number", "run_biaxial",
    "run_biaxial_series",
]  # fmt: skip
