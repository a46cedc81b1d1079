"""A user's soil end to end (``poro2d sand``): laboratory description in, density-aware 2D porosity out."""

from poro2d.sand.case import SandCase, load_sand_case
from poro2d.sand.result import SandResult
from poro2d.sand.run import check_soil, run_sand

__all__ = ["SandCase", "SandResult", "load_sand_case", "check_soil", "run_sand"]
