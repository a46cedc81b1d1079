"""poro2d: 2D porosities for discrete element studies in geomechanics.

Layers (see ARCHITECTURE.md): ``porosity`` (3D-to-2D conversions, Eqs. 1-12 of
Wang, Jacobs & Ziegler), ``dem`` (the 2D DEM engine), ``specimen`` (grading
curves and multilayer compaction), ``criterion`` (the paper's Fig. 3),
``shear`` (direct shear tests), ``report`` and ``sweep``.

The main entry points are also names of this package, so that a script or a notebook imports
from one place (``from poro2d import run_sand, load_sand_case, Store``); each is the same object
as at its own module (the table :data:`PUBLIC`). They are imported on first use (PEP 562), so
``import poro2d`` stays light: it imports neither numba nor any of those modules.
"""

from importlib import import_module
from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("poro2d")
except PackageNotFoundError:  # running from a source tree that was not installed
    __version__ = "0+unknown"

#: top-level name -> (module, name in that module)
PUBLIC: dict[str, tuple[str, str]] = {
    # conversions and the laboratory state
    "convert_all": ("poro2d.porosity", "convert_all"),
    "parabolic": ("poro2d.porosity", "parabolic"),
    "relative_density": ("poro2d.porosity", "relative_density"),
    "void_ratio": ("poro2d.porosity", "void_ratio"),
    "porosity_from_void_ratio": ("poro2d.porosity", "porosity_from_void_ratio"),
    # grading curves and specimens
    "GradingCurve": ("poro2d.grading", "GradingCurve"),
    "preset_grading": ("poro2d.grading", "preset_grading"),
    "SpecimenSpec": ("poro2d.specimen.compaction", "SpecimenSpec"),
    "prepare_specimen": ("poro2d.specimen.compaction", "prepare_specimen"),
    # a soil of one's own
    "check_soil": ("poro2d.sand", "check_soil"),
    "load_sand_case": ("poro2d.sand", "load_sand_case"),
    "run_sand": ("poro2d.sand", "run_sand"),
    # the criterion (Fig. 3)
    "CriterionCase": ("poro2d.criterion", "CriterionCase"),
    "run_criterion": ("poro2d.criterion", "run_criterion"),
    # laboratory tests
    "ShearSeriesCase": ("poro2d.shear", "ShearSeriesCase"),
    "run_shear": ("poro2d.shear", "run_shear"),
    "BiaxialCase": ("poro2d.biaxial", "BiaxialCase"),
    "BiaxialSettings": ("poro2d.biaxial", "BiaxialSettings"),
    "run_biaxial": ("poro2d.biaxial", "run_biaxial"),
    "run_biaxial_series": ("poro2d.biaxial", "run_biaxial_series"),
    "CriticalStateCase": ("poro2d.critical_state", "CriticalStateCase"),
    "run_critical_state": ("poro2d.critical_state", "run_critical_state"),
    "run_critical_states": ("poro2d.critical_state", "run_critical_states"),
    # studies
    "PaperCase": ("poro2d.paper", "PaperCase"),
    "paper_preset": ("poro2d.criterion.config", "paper_preset"),
    "run_paper": ("poro2d.paper", "run_paper"),
    "RelationCase": ("poro2d.sweep.relation", "RelationCase"),
    "run_relation": ("poro2d.sweep.relation", "run_relation"),
    "CalibrationCase": ("poro2d.calibration", "CalibrationCase"),
    "run_calibration": ("poro2d.calibration", "run_calibration"),
    "synthetic_lab": ("poro2d.calibration", "synthetic_lab"),
    # export to other DEM codes, and their runs of a specimen
    "export_specimen": ("poro2d.interop.exported", "export_specimen"),
    "load_specimen": ("poro2d.interop.specimen_data", "from_checkpoint"),
    "export_lammps": ("poro2d.interop.lammps", "write_specimen"),
    "export_yade": ("poro2d.interop.yade", "write_specimen"),
    "export_pfc": ("poro2d.interop.pfc", "write_specimen"),
    "export_csv": ("poro2d.interop.csv_table", "write_specimen"),
    "RestCase": ("poro2d.interop.settled", "RestCase"),
    "compare_lammps": ("poro2d.interop.agreement", "compare"),
    "settle_poro2d": ("poro2d.interop.agreement", "settle_poro2d"),
    "settle_lammps": ("poro2d.interop.agreement", "settle_lammps"),
    "settle_yade": ("poro2d.interop.yade_run", "settle_yade"),
    # where runs run and where they keep their files; bad input
    "RunOptions": ("poro2d.execute", "RunOptions"),
    "Store": ("poro2d.store", "Store"),
    "InputError": ("poro2d.errors", "InputError"),
}

__all__ = ["__version__", *PUBLIC]


def __getattr__(name: str):
    """The object ``name`` of :data:`PUBLIC`, imported from its module on first use."""
    try:
        module, attr = PUBLIC[name]
    except KeyError:
        raise AttributeError(f"module 'poro2d' has no attribute {name!r}") from None
    value = getattr(import_module(module), attr)
    globals()[name] = value  # later reads skip this function
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(PUBLIC))
