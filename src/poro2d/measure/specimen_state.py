"""Homogeneity and stress state of a prepared specimen.

The box is cut into horizontal bands of equal height. In each band:

- the porosity, with disks clipped exactly at the band's edges (so a band's value does
  not depend on where disk centres happen to fall);
- the average stress of the disks centred in it (Love-Weber, :func:`average_stress`):
  vertical sigma_v and horizontal sigma_h, compression positive, and K0 = sigma_h / sigma_v;
- beside sigma_v, the geostatic stress of the material above the band's middle plus the
  plate: F_top / W + rho_s g (1 - n_above) (z_top - z), per unit area of the 2D box
  (stresses are forces per metre of thickness per metre of width, i.e. Pa).

A specimen built by gravity deposition should show sigma_v close to the geostatic line
(less where the side walls carry part of the weight by friction, Janssen's silo effect)
and K0 of the order of Jaky's 1 - sin(phi); one built by radius expansion locks in a
stress that does not grow with depth.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from poro2d.errors import check_int
from poro2d.measure.porosity import porosity_rect
from poro2d.measure.stress import average_stress
from poro2d.typed_result import TypedResult


@dataclass(eq=False)
class StateBand(TypedResult):
    """One horizontal band of a specimen: its heights, porosity, stresses, K0 and the geostatic sigma_v.

    ``k0`` is None where sigma_v is not compressive.
    """

    z_bottom_m: float
    z_top_m: float
    z_mid_m: float
    porosity: float
    sigma_v_pa: float
    sigma_h_pa: float
    k0: float | None
    sigma_v_geostatic_pa: float


@dataclass(eq=False)
class SpecimenStateResult(TypedResult):
    """A specimen's homogeneity and stress state by band; the accepted one's is ``specimen_state.json``.

    ``bands``: one row per band, bottom to top (heights, porosity, sigma_v, sigma_h, K0 and
    the geostatic sigma_v); the summary over them; ``trial_porosity``: the criterion's n2D
    of the accepted specimen (None for a state measured outside a criterion run).
    """

    PARTS: ClassVar[dict[str, type[TypedResult]]] = {"bands": StateBand}

    bands: list[StateBand]
    porosity_definition: str
    porosity_mean: float
    porosity_sd: float
    porosity_range: float
    k0_mean: float | None
    k0_sd: float | None
    sigma_v_bottom_over_geostatic: float | None
    stress_sign: str
    trial_porosity: float | None = None


def band_edges(top: float, bands: int) -> np.ndarray:
    return np.linspace(0.0, top, bands + 1)


def specimen_state(
    sim, width: float, top: float, bands: int = 8, trial_porosity: float | None = None
) -> SpecimenStateResult:
    """Porosity, sigma_v, sigma_h, K0 and the geostatic sigma_v per band, bottom to top.

    ``top``: the height of the top plate. Returns the bands and a summary (porosity
    spread, mean K0, the ratio of measured to geostatic sigma_v at the bottom band), with
    ``trial_porosity`` (the criterion's n2D of the specimen) as given.
    """
    check_int("bands", bands, 2, 200)
    p = sim.particles
    edges = band_edges(top, bands)
    g = -sim.gravity[1]
    rho_s = float(np.mean(p.density)) if p.n else 0.0
    f_top = float(sim.wall_force("top")[1]) / p.thickness  # N/m, upward push on the plate
    rows: list[StateBand] = []
    for k in range(bands):
        y0, y1 = edges[k], edges[k + 1]
        s = average_stress(sim, 0.0, y0, width, y1)  # tension positive
        zc = 0.5 * (y0 + y1)
        n_above = porosity_rect(p.pos, p.radius, 0.0, zc, width, top)
        geo = f_top / width + rho_s * g * (1.0 - n_above) * (top - zc)
        sv, sh = -float(s[1, 1]), -float(s[0, 0])
        rows.append(StateBand(
            z_bottom_m=float(y0), z_top_m=float(y1), z_mid_m=float(zc),
            porosity=porosity_rect(p.pos, p.radius, 0.0, y0, width, y1),
            sigma_v_pa=sv, sigma_h_pa=sh, k0=sh / sv if sv > 0 else None, sigma_v_geostatic_pa=geo,
        ))  # fmt: skip
    por = np.array([r.porosity for r in rows])
    k0 = np.array([r.k0 for r in rows if r.k0 is not None])
    bottom = rows[0]
    geo0 = bottom.sigma_v_geostatic_pa
    return SpecimenStateResult(
        bands=rows,
        porosity_definition="disk area clipped to the band / band area",
        porosity_mean=float(por.mean()),
        porosity_sd=float(por.std(ddof=1)),
        porosity_range=float(por.max() - por.min()),
        k0_mean=float(k0.mean()) if k0.size else None,
        k0_sd=float(k0.std(ddof=1)) if k0.size > 1 else None,
        sigma_v_bottom_over_geostatic=bottom.sigma_v_pa / geo0 if geo0 > 0 else None,
        stress_sign="compression positive; per metre of thickness and of width (Pa)",
        trial_porosity=trial_porosity,
    )


__all__ = ["SpecimenStateResult", "StateBand", "band_edges", "specimen_state"]
