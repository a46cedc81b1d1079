"""Direct shear tests in a split box of moving walls (the paper's section 4, Fig. 8)."""

from poro2d.shear.box import SplitBox, build_split_box
from poro2d.shear.case import ShearCase
from poro2d.shear.fit import MohrCoulombFit, mohr_coulomb, peak, smooth
from poro2d.shear.lab import LabData, read_lab_csv
from poro2d.shear.run import ShearSeriesCase, run_shear
from poro2d.shear.series import ShearSeries
from poro2d.shear.settings import ShearSettings, inertial_number
from poro2d.shear.single import DirectShearTest
from poro2d.specimen.saved import Specimen

__all__ = [
    "DirectShearTest", "LabData", "MohrCoulombFit", "ShearCase", "ShearSeries", "ShearSeriesCase",
    "ShearSettings", "Specimen", "SplitBox", "build_split_box", "inertial_number", "mohr_coulomb", "peak",
    "read_lab_csv", "run_shear", "smooth",
]  # fmt: skip
