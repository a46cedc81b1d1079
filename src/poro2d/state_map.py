"""A laboratory critical-state line, the state parameter, and the two maps of a state into 2D.

Sand behaves by its distance from the critical state, the state parameter
psi = e - e_cs(p') (Been & Jefferies 1985), far better than by its relative density. This
module holds the laboratory's side of that and the arithmetic of the maps:

* :class:`LabCriticalStateLine`: e_cs(p') as laboratories publish it, a power line
  e_cs = e_Gamma - lambda (p' / p_ref)^xi (Li & Wang 1998), a semi-log line
  e_cs = e_Gamma - lambda ln(p' / p_ref) (xi absent), or a table of (p', e_cs) points read
  linearly in ln p'; :data:`PUBLISHED_LINES` the lines poro2d knows by name, with sources.
* :func:`bolton_dilatancy`: Bolton's (1986) relative dilatancy index I_R = Dr (Q - ln p') - R
  and the peak friction above critical, 5 I_R in plane strain and 3 I_R in triaxial compression.
* :func:`map_state`: one laboratory state at the test stress, mapped by relative density,
  e2D = e2D,max - Dr (e2D,max - e2D,min) (Salot et al. 2009), and by the normalised state
  parameter, e2D = e_cs,2D(p') + psi / (e_max - e_min) (e2D,max - e2D,min), given the 2D
  critical-state line (``poro2d critical-state --pressure ...``) and the 2D preparation's ends.

Void ratios throughout; a 2D void ratio is (1 - phi) / phi of the disks' solid fraction phi,
and a porosity n = e / (1 + e). Pressures in kPa.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from poro2d.errors import InputError, check_range, is_number
from poro2d.lab_table import read_lab_table

#: the mean stresses a line may be read at (kPa): the laboratory range of sands, below crushing
PRESSURE_RANGE_KPA = (1.0, 10_000.0)


@dataclass(frozen=True)
class LabCriticalStateLine:
    """A laboratory critical-state line e_cs(p') (see the module): ``xi`` None for the semi-log
    form; ``points`` ((p', e_cs) pairs) for a table, which replaces the formula."""

    e_gamma: float | None = None
    lam: float | None = None
    xi: float | None = None
    p_ref_kpa: float = 1.0
    points: tuple[tuple[float, float], ...] = ()
    source: str = ""

    def __post_init__(self) -> None:
        if self.points:
            self._check_points()
            return
        check_range("e_gamma", self.e_gamma, 0.0, 5.0, lo_open=True)
        check_range("lambda", self.lam, 0.0, 1.0)
        check_range("p_ref_kpa", self.p_ref_kpa, 0.0, None, lo_open=True)
        if self.xi is not None:
            check_range("xi", self.xi, 0.0, 2.0, lo_open=True)

    def _check_points(self) -> None:
        if len(self.points) < 2:
            raise InputError("points", list(self.points), "at least two (p' kPa, e_cs) pairs")
        for k, pair in enumerate(self.points):
            if len(pair) != 2 or not all(is_number(v) for v in pair):
                raise InputError(f"points[{k}]", pair, "a pair of numbers (p' kPa, e_cs)")
            check_range(f"points[{k}] p'", pair[0], *PRESSURE_RANGE_KPA)
            check_range(f"points[{k}] e_cs", pair[1], 0.0, 5.0, lo_open=True)
        p = [q for q, _ in self.points]
        if any(b <= a for a, b in zip(p, p[1:], strict=False)):
            raise InputError("points", list(self.points), "pressures rising from one pair to the next")

    def void_ratio_at(self, p_kpa: float) -> float:
        """e_cs at the mean stress ``p_kpa`` (a table is not extrapolated)."""
        check_range("p'", p_kpa, *PRESSURE_RANGE_KPA)
        if self.points:
            p = np.log([q for q, _ in self.points])
            lo, hi = self.points[0][0], self.points[-1][0]
            if not lo <= p_kpa <= hi:
                raise InputError("p'", p_kpa, f"[{lo:g}, {hi:g}] kPa, the range of the line's points")
            return float(np.interp(math.log(p_kpa), p, [e for _, e in self.points]))
        x = p_kpa / self.p_ref_kpa
        return self.e_gamma - self.lam * (x**self.xi if self.xi is not None else math.log(x))

    def text(self) -> str:
        """The line as written: its formula or its points, and its source."""
        if self.points:
            body = "points " + ", ".join(f"({p:g} kPa, {e:g})" for p, e in self.points)
        elif self.xi is not None:
            body = f"e_cs = {self.e_gamma:g} - {self.lam:g} (p'/{self.p_ref_kpa:g} kPa)^{self.xi:g}"
        else:
            body = f"e_cs = {self.e_gamma:g} - {self.lam:g} ln(p'/{self.p_ref_kpa:g} kPa)"
        return body + (f" ({self.source})" if self.source else "")


#: published laboratory lines by name, each with its soil's e_max and e_min (the same source)
PUBLISHED_LINES: dict[str, tuple[LabCriticalStateLine, float, float]] = {
    "toyoura": (
        LabCriticalStateLine(
            e_gamma=0.934,
            lam=0.019,
            xi=0.7,
            p_ref_kpa=101.0,
            source="Toyoura sand, drained and undrained triaxial tests of Verdugo & Ishihara 1996 "
            "(Soils Found. 36(2)), the power line fitted by Li & Wang 1998 (J. Geotech. Geoenviron. "
            "Eng. 124(12)); e_max 0.977, e_min 0.597",
        ),
        0.977,
        0.597,
    ),
}


def published_line(name: str) -> tuple[LabCriticalStateLine, float, float]:
    """(line, e_max, e_min) of a published sand by name (:data:`PUBLISHED_LINES`)."""
    key = str(name).strip().lower()
    if key not in PUBLISHED_LINES:
        raise InputError("critical-state line", name, ", ".join(sorted(PUBLISHED_LINES)))
    return PUBLISHED_LINES[key]


@dataclass(frozen=True)
class Dilatancy:
    """Bolton's (1986) numbers at one state: I_R (clipped to [0, 4]) and phi_peak - phi_cs (deg)."""

    relative_dilatancy_index: float
    plane_strain_deg: float
    triaxial_deg: float


def bolton_dilatancy(dr: float, p_kpa: float, q: float = 10.0, r: float = 1.0) -> Dilatancy:
    """I_R = Dr (Q - ln p') - R (p' in kPa), clipped to [0, 4] as Bolton bounds it; the peak
    friction above critical is 5 I_R in plane strain and 3 I_R in triaxial compression (deg).
    Q about 10 and R about 1 for quartz sands (Bolton 1986)."""
    check_range("Dr", dr, 0.0, 1.0)
    check_range("p'", p_kpa, *PRESSURE_RANGE_KPA)
    index = min(4.0, max(0.0, dr * (q - math.log(p_kpa)) - r))
    return Dilatancy(index, 5.0 * index, 3.0 * index)


@dataclass(frozen=True)
class MappedState:
    """One laboratory state at p' and its 2D void ratio by each map.

    ``psi_lab`` = e - e_cs(p') and ``psi_norm`` = psi_lab / (e_max - e_min) in the laboratory;
    ``e2d_by_dr`` and ``e2d_by_state`` the 2D void ratios of the two maps, ``psi2d_by_dr`` the
    normalised 2D state parameter of the relative-density answer (what its specimen would be
    at p'); ``state_within_ends``: whether the state map's answer lies between the 2D ends (a
    preparation can reach it).
    """

    p_kpa: float
    e_lab: float
    dr: float
    e_cs_lab: float
    psi_lab: float
    psi_norm: float
    e_cs_2d: float
    e2d_max: float
    e2d_min: float
    e2d_by_dr: float
    e2d_by_state: float
    psi2d_by_dr: float
    state_within_ends: bool

    @staticmethod
    def porosity(e: float) -> float:
        """n = e / (1 + e)."""
        return e / (1.0 + e)


def map_state(
    e_lab: float, e_max: float, e_min: float, line: LabCriticalStateLine, p_kpa: float,
    e_cs_2d: Callable[[float], float], e2d_max: float, e2d_min: float,
) -> MappedState:  # fmt: skip
    """The laboratory state ``e_lab`` (between ``e_min`` and ``e_max``) at the mean stress
    ``p_kpa`` mapped into 2D by relative density and by the normalised state parameter (module).

    ``e_cs_2d(p)``: the 2D line (:meth:`poro2d.critical_state.line.LineFit.void_ratio_at`);
    ``e2d_max``, ``e2d_min``: the 2D preparation's loosest and densest void ratios.
    """
    check_range("e_max", e_max, 0.0, 5.0, lo_open=True)
    check_range("e_min", e_min, 0.0, e_max, lo_open=True, hi_open=True)
    check_range("e", e_lab, e_min, e_max)
    check_range("e2d_max", e2d_max, 0.0, 5.0, lo_open=True)
    check_range("e2d_min", e2d_min, 0.0, e2d_max, lo_open=True, hi_open=True)
    dr = (e_max - e_lab) / (e_max - e_min)
    e_cs = line.void_ratio_at(p_kpa)
    psi = e_lab - e_cs
    psi_norm = psi / (e_max - e_min)
    span = e2d_max - e2d_min
    cs2d = float(e_cs_2d(p_kpa))
    by_dr = e2d_max - dr * span
    by_state = cs2d + psi_norm * span
    return MappedState(
        p_kpa=p_kpa, e_lab=e_lab, dr=dr, e_cs_lab=e_cs, psi_lab=psi, psi_norm=psi_norm, e_cs_2d=cs2d,
        e2d_max=e2d_max, e2d_min=e2d_min, e2d_by_dr=by_dr, e2d_by_state=by_state,
        psi2d_by_dr=(by_dr - cs2d) / span, state_within_ends=bool(e2d_min <= by_state <= e2d_max),
    )  # fmt: skip


def read_lab_line(text: str) -> tuple[LabCriticalStateLine, float | None, float | None]:
    """A laboratory line by a published name (with its e_max, e_min) or from a CSV file of
    ``p_kpa,e_cs`` rows (extremes then come from elsewhere: None)."""
    if str(text).strip().lower() in PUBLISHED_LINES:
        return published_line(text)
    if not str(text).lower().endswith(".csv"):
        raise InputError(
            "lab line", text, f"{', '.join(sorted(PUBLISHED_LINES))}, or a CSV of p_kpa,e_cs rows"
        )
    table = read_lab_table(text)
    if not table.has("p_kpa", "e_cs"):
        raise InputError(
            "lab line", text, "a CSV with columns p_kpa,e_cs", f"its header: {','.join(table.header)}"
        )
    p = table.column("p_kpa", *PRESSURE_RANGE_KPA, unit="kPa")
    e = table.column("e_cs", 0.01, 5.0)
    return line_of_table(list(zip(p.tolist(), e.tolist(), strict=True)), source=str(text)), None, None


def line_of_table(points: Sequence[Sequence[float]], source: str = "") -> LabCriticalStateLine:
    """A laboratory line from (p' kPa, e_cs) pairs, sorted by pressure."""
    pairs = tuple(sorted((tuple(p) for p in points), key=lambda pe: pe[0] if is_number(pe[0]) else 0.0))
    return LabCriticalStateLine(points=pairs, source=source)


__all__ = [
    "PRESSURE_RANGE_KPA",
    "PUBLISHED_LINES",
    "Dilatancy",
    "LabCriticalStateLine",
    "MappedState",
    "bolton_dilatancy",
    "line_of_table",
    "map_state",
    "published_line",
    "read_lab_line",
]
