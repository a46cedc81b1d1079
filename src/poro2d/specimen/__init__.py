"""Specimen layer: grading curves, drawing disk radii, non-overlapping placement.

``grading`` turns sieve data (mm, percent passing by mass, an up-scaling factor) into a
:class:`GradingCurve` and draws disk radii whose area follows it; ``placement`` puts a list
of radii into a rectangular band without overlap (at reduced radius when the band is dense).
"""

from poro2d.grading import (
    PAPER_UPSCALE,
    GradingCurve,
    draw_disks,
    max_deviation,
    paper_grading,
    realised_curve,
)
from poro2d.specimen.placement import Band, Placement, place_disks, solid_fraction

__all__ = [
    "PAPER_UPSCALE",
    "Band",
    "GradingCurve",
    "Placement",
    "draw_disks",
    "max_deviation",
    "paper_grading",
    "place_disks",
    "realised_curve",
    "solid_fraction",
]
