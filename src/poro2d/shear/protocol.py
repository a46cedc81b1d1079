"""The direct shear test's names in one place, for code written against the single module.

The test lives in small modules: :mod:`~poro2d.shear.settings` (``ShearSettings``),
:mod:`~poro2d.shear.single` (``DirectShearTest``), :mod:`~poro2d.shear.curve` (the
recorded curve), :mod:`~poro2d.shear.pool` (the process pool), :mod:`~poro2d.shear.series`
(``ShearSeries``), :mod:`~poro2d.shear.outputs` (files) and :mod:`~poro2d.shear.run`
(``run_shear``). New code imports from those or from :mod:`poro2d.shear`.
"""

from poro2d.shear.curve import CURVE_COLUMNS
from poro2d.shear.outputs import folder_name
from poro2d.shear.outputs import read_curve_csv as _read_csv
from poro2d.shear.pool import execute_jobs, job_label
from poro2d.shear.run import run_shear
from poro2d.shear.series import ShearSeries
from poro2d.shear.settings import ShearSettings, inertial_number
from poro2d.shear.single import DirectShearTest, ProgressFn
from poro2d.shear.specimen_file import resolve_specimen, specimen_box

__all__ = [
    "CURVE_COLUMNS", "DirectShearTest", "ProgressFn", "ShearSeries", "ShearSettings", "_read_csv",
    "execute_jobs", "folder_name", "inertial_number", "job_label", "resolve_specimen", "run_shear",
    "specimen_box",
]  # fmt: skip
