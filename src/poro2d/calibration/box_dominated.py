"""The design points a direct shear calibration leaves out: those with box-dominated tests.

A test is box-dominated when its shear plane carries outside 0.7-1.3 times the plate's load at the
peak or its stress never peaked (:mod:`poro2d.shear.box_dominated`): its tau/sigma is the box's, not
the soil's. A surrogate fitted through such strengths would calibrate the frictions to the box, so
:func:`poro2d.calibration.run.run_calibration` leaves every design point with such a test out of
the fit (unless told to keep them), records them (:class:`BoxDominatedPoints`) and refuses when too
few points are left (:class:`TooFewPoints`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import ClassVar

from poro2d.calibration.evaluations import DesignPoint
from poro2d.paper_data import QUICK_BOX_SOIL_LIKE
from poro2d.shear.box_dominated import MEANING as BOX_DOMINATED
from poro2d.shear.box_dominated import PLANE_LOAD_BAND
from poro2d.typed_result import TypedResult


@dataclass(eq=False)
class BoxDominatedPoint(TypedResult):
    """A design point with box-dominated tests: its pair, how many of its tests were and the first
    one's verdict (with its specimen and stress)."""

    particle_friction: float
    rolling_friction: float
    tests: int
    note: str


@dataclass(eq=False)
class BoxDominatedPoints(TypedResult):
    """The design points of a direct shear calibration with a box-dominated test
    (:mod:`poro2d.shear.box_dominated`): how many of how many (``flagged``), how many of them were
    left out of the fit (``left_out``: all, unless the calibration was told to keep them), the band
    of the plane's load a test had to stay in, each point, and the calibration's sentence on them."""

    flagged: int
    left_out: int
    design_points: int
    plane_load_band: list[float]
    points: list[BoxDominatedPoint]
    note: str = ""

    PARTS: ClassVar[dict[str, type[TypedResult]]] = {"points": BoxDominatedPoint}


class TooFewPoints(RuntimeError):
    """Too few design points are left for the surrogate once the box-dominated ones are left out: no
    answer (one line at the command)."""


def quick_box_note(disks: int, max_displacement: float) -> str:
    """Where the quick box of ``disks`` disks reads soil-like strength (``QUICK_BOX_SOIL_LIKE`` of
    paper_data, measured: docs/shear.md), and whether tests of ``max_displacement`` (m) are long
    enough to peak there."""
    fp, mu_r = QUICK_BOX_SOIL_LIKE["particle_friction"], QUICK_BOX_SOIL_LIKE["rolling_friction"]
    travel, share = QUICK_BOX_SOIL_LIKE["max_displacement"], QUICK_BOX_SOIL_LIKE["box_dominated_fraction"]
    short = (
        f": its tests of {1e3 * max_displacement:g} mm end before their peak (--max-displacement)"
        if max_displacement < travel
        else ""
    )
    return (
        f"the quick box ({disks} disks) measures soil-like strength only for f_p <= {fp:g} and mu_r <= "
        f"{mu_r:g}, sheared {1e3 * travel:g} mm, and even there {share:.0%} of its tests were box-dominated "
        f"(docs/shear.md){short}"
    )


def box_dominated_points(
    flagged: list[list], table: list[DesignPoint], fewest: int, keep: bool
) -> BoxDominatedPoints:
    """The design points of ``table`` with box-dominated tests (``flagged``: per point, the rows of its
    tests that are), left out of the fit unless ``keep``. Refused (no answer) when fewer than ``fewest``
    are left (the quadratic surrogate's least, :func:`poro2d.calibration.run.min_points`)."""
    points = [
        BoxDominatedPoint(entry.particle_friction, entry.rolling_friction, len(rows),
                          f"{rows[0].specimen} at {rows[0].sigma:g} kPa: {rows[0].box_note}")
        for entry, rows in zip(table, flagged, strict=True)
        if rows
    ]  # fmt: skip
    left_out = 0 if keep else len(points)
    record = BoxDominatedPoints(len(points), left_out, len(table), list(PLANE_LOAD_BAND), points)
    left = len(table) - left_out
    if left < fewest:
        raise TooFewPoints(
            f"{left_out} of {len(table)} design points are box-dominated ({BOX_DOMINATED}) and are "
            f"left out: the {left} left cannot fit the quadratic surrogate, which needs {fewest}; "
            "narrow --fp-range and --mu-r-range to where the box reads soil-like strength, shear further "
            "(--max-displacement), use a larger specimen, or fit the box as it is (--keep-box-dominated; "
            "docs/calibration.md)"
        )
    return record


def with_box_note(
    points: BoxDominatedPoints, quick: bool, disks: int, max_displacement: float
) -> BoxDominatedPoints:
    """``points`` with the calibration's sentence on them: how many design points were box-dominated,
    whether they were left out and, for the quick box, where it measured soil-like strength
    (``QUICK_BOX_SOIL_LIKE`` of paper_data) and whether tests of ``max_displacement`` (m) peak there."""
    fate = (
        ""
        if not points.flagged
        else ", left out of the fit"
        if points.left_out == points.flagged
        else ", kept in the fit (--keep-box-dominated): the frictions describe the box, not the soil"
    )
    flagged = f"{points.flagged} of {points.design_points} design points were box-dominated"
    text = f"{flagged} ({BOX_DOMINATED}){fate}"
    quick_note = quick_box_note(disks, max_displacement) if quick else None
    return replace(points, note=f"{quick_note}; {text}" if quick_note else text)


__all__ = [
    "BoxDominatedPoint", "BoxDominatedPoints", "TooFewPoints", "box_dominated_points", "quick_box_note",
    "with_box_note",
]  # fmt: skip
