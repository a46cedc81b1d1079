"""poro2d: 2D porosities for discrete element studies in geomechanics.

Layers (see ARCHITECTURE.md): ``porosity`` (3D-to-2D conversions, Eqs. 1-12 of
Wang, Jacobs & Ziegler), ``dem`` (the 2D DEM engine), ``specimen`` (grading
curves and multilayer compaction), ``criterion`` (the paper's Fig. 3),
``shear`` (direct shear tests), ``report`` and ``sweep``.
"""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("poro2d")
except PackageNotFoundError:  # running from a source tree that was not installed
    __version__ = "0+unknown"

__all__ = ["__version__"]
