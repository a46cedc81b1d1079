"""The porosity of the specimen itself, measured away from its walls and its free surface.

The paper's box porosity n' = 1 - sum(pi r^2) / (W H_plate) counts the whole box under the
top plate. The plate rests on a few high disks, so the band just under it is mostly gap
(its porosity is about twice the interior's), and flat walls loosen the layer of disks
against them. Both are properties of the box, not of the sand: a user who wants the
porosity of the packing, as a field measurement would give it, needs it measured where
neither reaches. :func:`measure_specimen` gives, in one :class:`SpecimenPorosity` (its
figure is ``plot_local_porosity`` (``report/specimen_figures.py``)):

- the free surface of the packing, h(x), and how the plate sits on it (mean and largest
  gap, the share of the plate's width in contact, the disks touching it;
  :mod:`poro2d.measure.surface`);
- the porosity of measurement circles (PFC's measurement circles) tiling an interior
  region that keeps ``margin_d50`` median diameters from every wall and from the lowest
  level of the free surface, with the porosity of the whole interior rectangle as a
  second estimate (:mod:`poro2d.measure.interior`);
- the Laguerre (power, radical) tessellation of the disks in the box: one convex cell per
  disk, tiling the box exactly, giving a local porosity per disk and a third interior
  estimate (:mod:`poro2d.measure.laguerre`).

Disks are clipped exactly at the edges of every region (no counting of centres), so a
value does not depend on where centres happen to fall.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from poro2d.errors import InputError, as_float_array, check_range
from poro2d.io_utils import Provenance
from poro2d.measure.disks import check_d50, check_specimen
from poro2d.measure.interior import DEFAULT_CIRCLE_D50, DEFAULT_MARGIN_D50, InteriorRegions, interior_regions
from poro2d.measure.laguerre import LaguerreCells, laguerre_cells, laguerre_porosity
from poro2d.measure.porosity import box_porosity, disk_area
from poro2d.measure.surface import lid_height_at, plate_from_profile, profile_bins, surface_profile
from poro2d.typed_result import NOT_IN_FILE, TypedResult, part


@dataclass(frozen=True)
class PorosityDetails:
    """The arrays behind a :class:`SpecimenPorosity`, for figures and further analysis.

    ``surface_x``/``surface_h``: the free surface profile (m); ``interior``: the measurement
    circles and the interior rectangle; ``cells``: the Laguerre cells with their local
    porosity.
    """

    surface_x: np.ndarray = field(repr=False)
    surface_h: np.ndarray = field(repr=False)
    interior: InteriorRegions
    cells: LaguerreCells


#: the numbers :func:`measure_specimen` gives, in the order of the file
MEASURES = (
    "box_porosity", "interior_porosity", "interior_porosity_std", "interior_porosity_min",
    "interior_porosity_max", "interior_regions", "interior_rect_porosity", "laguerre_interior_porosity",
    "margin_d50", "circle_radius_m", "surface_gap_mean_m", "surface_gap_mean_d50", "surface_gap_max_m",
    "plate_contact_fraction", "plate_touching_disks", "d50_m", "surface_level_m",
)  # fmt: skip
#: the counts among the measures (written as ints); the others are floats
COUNTS = ("interior_regions", "plate_touching_disks")


@dataclass(eq=False)
class SpecimenPorosity(TypedResult):
    """Porosities of a specimen in a box under a top plate, and how the plate sits on it.

    - ``box_porosity``: the paper's n' = 1 - sum(pi r^2) / (W H_plate): whole disks, overlaps
      not subtracted, the gap under the plate included;
    - ``interior_porosity`` (mean over the measurement circles), with ``_std`` (ddof 1),
      ``_min``, ``_max`` and ``interior_regions`` (how many circles): the specimen's own
      porosity, ``margin_d50`` d50 away from walls and free surface;
    - ``interior_rect_porosity``: the whole interior rectangle (disks clipped exactly);
    - ``laguerre_interior_porosity``: disk area over Laguerre cell area, disks centred in the
      interior rectangle;
    - ``surface_*``, ``plate_*``: the gap between plate and free surface (m and d50), the
      share of the plate's width in contact, the disks touching the plate;
    - ``surface_level_m``: the free surface's lowest smoothed level, the interior's top plus
      the margin.

    The same record is the accepted specimen's ``specimen_porosity.json``, which adds the
    criterion's ``trial_porosity`` and the ``provenance``; a specimen too small to measure
    has there only ``note`` (why) beside them. Every key is written only when set, so
    :func:`measure_specimen` gives the measures alone. Measures are kept as plain Python
    floats and ints (JSON-ready). ``details`` holds the arrays (not a key of the file).
    """

    OPTIONAL = (*MEASURES, "trial_porosity", "note", "provenance")

    box_porosity: float | None = None
    interior_porosity: float | None = None
    interior_porosity_std: float | None = None
    interior_porosity_min: float | None = None
    interior_porosity_max: float | None = None
    interior_regions: int | None = None
    interior_rect_porosity: float | None = None
    laguerre_interior_porosity: float | None = None
    margin_d50: float | None = None
    circle_radius_m: float | None = None
    surface_gap_mean_m: float | None = None
    surface_gap_mean_d50: float | None = None
    surface_gap_max_m: float | None = None
    plate_contact_fraction: float | None = None
    plate_touching_disks: int | None = None
    d50_m: float | None = None
    surface_level_m: float | None = None
    trial_porosity: float | None = None
    note: str | None = None
    provenance: Provenance | None = None
    details: PorosityDetails | None = field(default=None, kw_only=True, repr=False, metadata=NOT_IN_FILE)

    def __post_init__(self) -> None:
        super().__post_init__()
        # a file's provenance read as its record
        self.provenance = part(Provenance, self.provenance)
        # NumPy scalars in, plain numbers out: the record is written as JSON
        for name in MEASURES:
            value = getattr(self, name)
            if value is not None:
                setattr(self, name, int(value) if name in COUNTS else float(value))


def measure_specimen(
    pos: Any,
    radius: Any,
    width: Any,
    plate_y: Any,
    d50: Any = None,
    margin_d50: Any = DEFAULT_MARGIN_D50,
    circle_d50: Any = DEFAULT_CIRCLE_D50,
    contact_tol_d50: Any = 0.05,
    lid: tuple[Any, Any] | None = None,
) -> SpecimenPorosity:
    """All porosity measures of a specimen in the box [0, width] x [0, plate_y].

    ``d50`` defaults to :func:`mass_d50` of the disks; ``margin_d50`` and ``circle_d50``
    as in :func:`interior_regions`, ``contact_tol_d50`` as in :func:`plate_surface`.
    ``lid``: (edges, heights) of a segmented lid under ``plate_y`` (the fill acceptance,
    :mod:`poro2d.criterion.lid`): the box porosity is then that of the area under the
    lid, and the gap and contact are measured to the lid instead of the flat plate.
    """
    pos, radius, width, plate_y = check_specimen(pos, radius, width, plate_y)
    d50 = check_d50(d50, radius)
    margin_d50 = check_range("margin_d50", margin_d50, 0.0)
    tol = check_range("contact_tol_d50", contact_tol_d50, 0.0) * d50
    x, h = surface_profile(pos, radius, width, profile_bins(width, d50))
    if lid is None:
        plate = plate_from_profile(h, pos, radius, plate_y, d50, tol)
        box = box_porosity(disk_area(radius), width, plate_y)
    else:
        edges, heights = _check_lid(lid, width, plate_y)
        plate = plate_from_profile(
            h,
            pos,
            radius,
            lid_height_at(edges, heights, x),
            d50,
            tol,
            lid_height_at(edges, heights, pos[:, 0]),
        )
        box = 1.0 - disk_area(radius) / float(np.sum(np.diff(edges) * heights))
    interior = interior_regions(pos, radius, width, plate_y, d50, margin_d50, circle_d50, profile=(x, h))
    cells = laguerre_cells(pos, radius, width, plate_y)
    return SpecimenPorosity(
        box_porosity=box,
        interior_porosity=interior.mean,
        interior_porosity_std=interior.std,
        interior_porosity_min=float(np.min(interior.porosity)),
        interior_porosity_max=float(np.max(interior.porosity)),
        interior_regions=interior.count,
        interior_rect_porosity=float(interior.rect_porosity),
        laguerre_interior_porosity=laguerre_porosity(cells, pos, radius, interior.rect),
        margin_d50=float(margin_d50),
        circle_radius_m=interior.circle_radius_m,
        surface_gap_mean_m=plate.gap_mean_m,
        surface_gap_mean_d50=plate.gap_mean_d50,
        surface_gap_max_m=plate.gap_max_m,
        plate_contact_fraction=plate.contact_fraction,
        plate_touching_disks=plate.touching_disks,
        d50_m=float(d50),
        surface_level_m=interior.surface_level_m,
        details=PorosityDetails(surface_x=x, surface_h=h, interior=interior, cells=cells),
    )


def _check_lid(lid: tuple[Any, Any], width: float, plate_y: float) -> tuple[np.ndarray, np.ndarray]:
    """A lid's (edges, heights): K + 1 rising edges from 0 to the width, K heights in (0, plate_y]."""
    edges = as_float_array("lid edges", lid[0])
    heights = as_float_array("lid heights", lid[1])
    if edges.ndim != 1 or heights.shape != (edges.size - 1,) or heights.size < 1:
        raise InputError("lid", f"{edges.size} edges, {heights.size} heights", "K + 1 edges and K heights")
    if not (np.all(np.diff(edges) > 0) and np.isclose(edges[0], 0.0) and np.isclose(edges[-1], width)):
        raise InputError("lid edges", edges.tolist(), f"rising from 0 to the width {width:g} m")
    if not (np.all(heights > 0.0) and np.all(heights <= plate_y)):
        raise InputError("lid heights", heights.tolist(), f"(0, {plate_y:g}] m")
    return edges, heights


__all__ = ["COUNTS", "MEASURES", "PorosityDetails", "SpecimenPorosity", "measure_specimen"]
