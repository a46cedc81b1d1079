"""The one way a figure is made and becomes a file: every figure of poro2d is drawn on
:func:`new_figure` and saved by :func:`save_figure`.

A figure has its own Agg canvas (no pyplot state, no display). One place decides the resolution
(:data:`DPI`) and how a file appears: written to a temporary in the same folder and renamed onto
its name, so that a reader (or a resumed run) never finds half a picture. The drawing functions
lay their figure out themselves (constrained or tight); saving changes nothing in the drawing.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from poro2d.io_utils import atomic_path

#: the resolution of every raster figure (dots per inch)
DPI = 150


def save_figure(fig: Figure, path: str | os.PathLike, *more: str | os.PathLike) -> Path:
    """Write ``fig`` to ``path``, and to each of ``more`` (the same drawing in another format),
    each atomically in the format its suffix names (PNG without one); then close ``fig``.

    Returns ``path``.
    """
    for target in (path, *more):
        target = Path(target)
        with atomic_path(target) as tmp:
            fig.savefig(tmp, dpi=DPI, format=target.suffix.lstrip(".") or "png")
    _close(fig)
    return Path(path)


def new_figure(*grid: int, figsize=None, layout=None, dpi=None, **axes):
    """A figure on its own Agg canvas and its axes (:meth:`~matplotlib.figure.Figure.subplots` of
    ``grid`` and ``axes``, as ``pyplot.subplots`` makes them): no pyplot state is touched, no display
    is needed, and the figure is freed with its last reference."""
    fig = Figure(figsize=figsize, layout=layout, dpi=dpi)
    FigureCanvasAgg(fig)
    return fig, fig.subplots(*grid, **axes)


def _close(fig: Figure) -> None:
    """Let pyplot forget ``fig``, if pyplot made it: a figure drawn on its own canvas is
    freed with its last reference, and pyplot is not imported for it."""
    pyplot = sys.modules.get("matplotlib.pyplot")
    if pyplot is not None:
        pyplot.close(fig)


__all__ = ["DPI", "new_figure", "save_figure"]
