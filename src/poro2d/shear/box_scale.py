"""A shear box against the standard's least size and the size from which 2D peaks stop changing.

A direct shear test measures its box as well as its material: the peak of a small box is
higher than the material's, and a box only a few grains tall cannot form its shear band
freely. Two yardsticks, both in units of the largest grain d_max:

- ASTM D3080 (laboratory boxes): width at least 10 d_max, height at least 6 d_max, and the
  width at least twice the height.
- 2D DEM studies of the direct shear box find peaks that no longer change with box size from a
  width of about 60 d_max and about 5000 disks on (Wang & Gutierrez 2010, Geotechnique 60:395;
  Deiminiat, Li & Zeng 2022, CivilEng 3:5). Below that, an angle belongs to the box: poro2d
  prints it as a box-scale angle.

The record is written with every series (its ``box_scale``) and printed wherever an angle is.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from poro2d.typed_result import TypedResult

#: ASTM D3080: least width and height in largest grains, least width-to-height ratio
ASTM_MIN_WIDTH_DMAX = 10.0
ASTM_MIN_HEIGHT_DMAX = 6.0
ASTM_MIN_ASPECT = 2.0
#: a box read back from its walls differs from the one asked for by microns (a 0.08 x 0.04 m box
#: reads 0.0400015 m tall): within this fraction of the least aspect it meets it
ASPECT_TOLERANCE = 1e-3
#: 2D DEM: the width (in d_max) and disk count from which peaks stop depending on the box
SIZE_INSENSITIVE_WIDTH_DMAX = 60.0
SIZE_INSENSITIVE_DISKS = 5000


@dataclass(eq=False)
class BoxScale(TypedResult):
    """A box's size against the two yardsticks (see the module): ratios, shortfalls, and the verdict.

    ``astm_shortfalls``: each ASTM D3080 ratio the box misses, as text (empty: it meets them);
    ``box_scale``: True when the box is below the size from which 2D peaks stop changing
    (its angles are the box's, not the material's).
    """

    width_m: float
    height_m: float
    d_max_m: float
    disks: int
    width_over_d_max: float
    height_over_d_max: float
    width_over_height: float
    astm_shortfalls: list[str]
    box_scale: bool

    @property
    def meets_astm(self) -> bool:
        return not self.astm_shortfalls

    def label(self) -> str:
        """``box-scale`` for a box below the size-insensitive one, else ``""``: put before an angle."""
        return "box-scale" if self.box_scale else ""

    def warning(self) -> str | None:
        """One line for the user when the box misses ASTM D3080's ratios; None when it meets them."""
        if self.meets_astm:
            return None
        return (
            f"the box is below ASTM D3080's least size ({'; '.join(self.astm_shortfalls)}): "
            "its angles describe this box more than the material"
        )

    def note(self) -> str:
        """The box in one line: its size in largest grains and what its angles are."""
        scale = (
            f"box-scale angles (size-insensitive 2D peaks need W >= {SIZE_INSENSITIVE_WIDTH_DMAX:g} d_max "
            f"and about {SIZE_INSENSITIVE_DISKS} disks)"
            if self.box_scale
            else "a box large enough for size-insensitive 2D peaks"
        )
        return (
            f"box W = {self.width_over_d_max:.1f} d_max, H = {self.height_over_d_max:.1f} d_max, "
            f"{self.disks} disks: {scale}"
        )


def box_scale_of(result: TypedResult | dict) -> BoxScale | None:
    """The ``box_scale`` of a series or strength result as its record (None when it has none).

    A result read back as a plain dict (``json.loads`` of its file) holds the record's dict.
    """
    scale = result.get("box_scale") if isinstance(result, dict) else result.box_scale
    if isinstance(scale, Mapping) and not isinstance(scale, BoxScale):
        return BoxScale.from_dict(scale)
    return scale


def box_scale(width: float, height: float, radii: np.ndarray) -> BoxScale:
    """The :class:`BoxScale` of a box ``width`` x ``height`` (m) holding disks of ``radii`` (m)."""
    d_max = 2.0 * float(np.max(radii))
    w, h = width / d_max, height / d_max
    short = []
    if w < ASTM_MIN_WIDTH_DMAX:
        short.append(f"W = {w:.1f} d_max < {ASTM_MIN_WIDTH_DMAX:g}")
    if h < ASTM_MIN_HEIGHT_DMAX:
        short.append(f"H = {h:.1f} d_max < {ASTM_MIN_HEIGHT_DMAX:g}")
    if width / height < ASTM_MIN_ASPECT * (1.0 - ASPECT_TOLERANCE):
        short.append(f"W/H = {width / height:.3f} < {ASTM_MIN_ASPECT:g}")
    n = int(np.size(radii))
    return BoxScale(
        width_m=float(width),
        height_m=float(height),
        d_max_m=d_max,
        disks=n,
        width_over_d_max=w,
        height_over_d_max=h,
        width_over_height=float(width / height),
        astm_shortfalls=short,
        box_scale=bool(w < SIZE_INSENSITIVE_WIDTH_DMAX or n < SIZE_INSENSITIVE_DISKS),
    )


__all__ = [
    "ASTM_MIN_ASPECT", "ASTM_MIN_HEIGHT_DMAX", "ASTM_MIN_WIDTH_DMAX", "BoxScale",
    "SIZE_INSENSITIVE_DISKS", "SIZE_INSENSITIVE_WIDTH_DMAX", "box_scale", "box_scale_of",
]  # fmt: skip
