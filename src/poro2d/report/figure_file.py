"""The one way a figure is made and becomes a file: every figure of poro2d is drawn on
:func:`new_figure` and saved by :func:`save_figure`.

A figure has its own Agg canvas (no pyplot state, no display). One place decides how a figure
looks in print and how it becomes files: the resolution of the raster (:data:`DPI`, 300 dots per
inch, what journals ask of line art in a raster), the vector drawing written beside every PNG
(:data:`VECTOR_SUFFIX`: SVG, scalable and editable, text kept as outlines so that it reads the same
without the fonts), and the colours (:data:`PALETTE`, readable by colour-blind readers). Each file
is written to a temporary in the same folder and renamed onto its name, so that a reader (or a
resumed run) never finds half a picture. The drawing functions lay their figure out themselves
(constrained or tight); saving changes nothing in the drawing.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

from matplotlib import rc_context
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.rcsetup import cycler  # matplotlib's own, checked cycler: no separate package to declare

from poro2d.io_utils import atomic_path

#: the resolution of every raster figure (dots per inch)
DPI = 300
#: the vector twin written beside every raster figure (same name, this suffix)
VECTOR_SUFFIX = ".svg"

# The colour-blind-safe palette of Okabe and Ito (2008, "Color Universal Design (CUD): how to
# make figures and presentations that are friendly to colorblind people"), as Wong (2011, "Points
# of view: Color blindness", Nature Methods 8, 441) gives it in RGB.
BLACK = "#000000"
ORANGE = "#E69F00"
SKY_BLUE = "#56B4E9"
BLUISH_GREEN = "#009E73"
YELLOW = "#F0E442"
BLUE = "#0072B2"
VERMILION = "#D55E00"
REDDISH_PURPLE = "#CC79A7"
#: a neutral grey for a reference line beside the coloured ones (grey reads alike to every eye)
GREY = "0.45"
#: the colours of series drawn in turn (normal stresses, seeds, frictions): the Okabe-Ito colours,
#: the pale yellow last, as it reads poorly as a thin line on white
PALETTE = (BLUE, VERMILION, BLUISH_GREEN, ORANGE, REDDISH_PURPLE, SKY_BLUE, BLACK, YELLOW)


def save_figure(fig: Figure, path: str | os.PathLike, *more: str | os.PathLike) -> Path:
    """Write ``fig`` to ``path`` and its vector twin (``path`` with :data:`VECTOR_SUFFIX`), and to
    each of ``more`` (the same drawing in another format), each atomically in the format its suffix
    names (PNG without one); then close ``fig``.

    Returns ``path``.
    """
    for target in figure_files(path, *more):
        with atomic_path(target) as tmp:
            fig.savefig(tmp, dpi=DPI, format=target.suffix.lstrip(".") or "png")
    _close(fig)
    return Path(path)


def figure_files(path: str | os.PathLike, *more: str | os.PathLike) -> list[Path]:
    """The files :func:`save_figure` writes for ``path`` and ``more``, in order, each once."""
    path = Path(path)
    targets = [path, *map(Path, more)]
    if path.suffix.lower() != VECTOR_SUFFIX:
        targets.insert(1, path.with_suffix(VECTOR_SUFFIX))
    return list(dict.fromkeys(targets))


def new_figure(*grid: int, figsize=None, layout=None, dpi=None, **axes):
    """A figure on its own Agg canvas and its axes (:meth:`~matplotlib.figure.Figure.subplots` of
    ``grid`` and ``axes``, as ``pyplot.subplots`` makes them), its series coloured from
    :data:`PALETTE`: no pyplot state is touched, no display is needed, and the figure is freed
    with its last reference."""
    fig = Figure(figsize=figsize, layout=layout, dpi=dpi)
    FigureCanvasAgg(fig)
    with rc_context({"axes.prop_cycle": cycler(color=PALETTE)}):
        return fig, fig.subplots(*grid, **axes)


def _close(fig: Figure) -> None:
    """Let pyplot forget ``fig``, if pyplot made it: a figure drawn on its own canvas is
    freed with its last reference, and pyplot is not imported for it."""
    pyplot = sys.modules.get("matplotlib.pyplot")
    if pyplot is not None:
        pyplot.close(fig)


__all__ = [
    "BLACK", "BLUE", "BLUISH_GREEN", "DPI", "GREY", "ORANGE", "PALETTE", "REDDISH_PURPLE", "SKY_BLUE",
    "VECTOR_SUFFIX", "VERMILION", "YELLOW", "figure_files", "new_figure", "save_figure",
]  # fmt: skip
