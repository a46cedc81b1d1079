"""The recorded curve of a direct shear test: one row per record, and what is read off it.

Shear stress is the horizontal force of the disks on the upper half (upper walls, upper
lip and the top plate's friction) over the nominal area ``W t``. The peak strength is
the maximum of the curve smoothed by a centred moving average over ``peak_window`` of
shear displacement.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from poro2d.dem import Simulation
from poro2d.dem.contacts import ContactSet
from poro2d.labtest.curve import CurveRow, curve_of
from poro2d.labtest.records import typed_parts
from poro2d.measure.fabric import FABRIC_COLUMNS, Fabric, measure_fabric
from poro2d.shear.box import UPPER_SIDE_WALLS, SplitBox
from poro2d.shear.fit import peak, smooth
from poro2d.shear.parts import EndValues, ForceBalance
from poro2d.shear.settings import ShearSettings, inertial_number
from poro2d.store import Store
from poro2d.typed_result import TypedResult, with_fields


@dataclass(eq=False)
@with_fields(Fabric, after="upper_wall_friction_kpa")
class ShearRow(CurveRow):
    """One record of a test's curve: a row of ``curve.csv``, its fields the columns in order.

    The stresses are over the nominal area ``W t``: the force on the upper half (``shear_stress_kpa``),
    on the lower half, across the shear plane and the upper disks' unbalanced part, the plate's
    push and its friction; displacements in mm, ``step`` counted from the start of shearing.
    ``plane_normal_stress_kpa`` is the vertical force the lower body exerts on the upper one
    across the shear plane (the normal stress the plane carries; compression positive), and
    ``upper_wall_friction_kpa`` the upward friction of the upper side walls on the disks:
    part of the plate's load that never reaches the plane (NaN in a curve of an earlier poro2d).
    The fabric of the disks last (:class:`~poro2d.measure.fabric.Fabric`: ``a_c`` ... ``rattler_fraction``).
    """

    step: int
    shear_displacement_mm: float
    shear_stress_kpa: float
    normal_stress_kpa: float
    plate_displacement_mm: float
    coordination_number: float
    lower_half_stress_kpa: float
    plane_stress_kpa: float
    upper_unbalanced_kpa: float
    plate_friction_kpa: float
    contacts_across_plane: int
    max_unbalanced_ratio: float
    inertial_number: float
    plane_normal_stress_kpa: float = math.nan
    upper_wall_friction_kpa: float = math.nan


#: columns a curve of an earlier poro2d lacks: read back as NaN
LATER_COLUMNS = ("plane_normal_stress_kpa", "upper_wall_friction_kpa", *FABRIC_COLUMNS)
ShearCurve = curve_of(
    ShearRow, "ShearCurve", __name__, later=LATER_COLUMNS,
    doc="A test's recorded curve: one float array per column of ``curve.csv`` (:data:`CURVE_COLUMNS`; the "
    "later ones NaN in a curve of an earlier poro2d), and a mapping of the names to them.",
)  # fmt: skip


#: the columns of ``curve.csv``, in order: the fields of a row
CURVE_COLUMNS = list(ShearCurve.COLUMNS)


def curve_columns(rows: list[ShearRow] | list[Mapping]) -> ShearCurve | None:
    """A curve's records as one float array per column (:meth:`ColumnCurve.of_rows`), None without rows."""
    return ShearCurve.of_rows(rows) if rows else None


def read_curve(store: Store, name: str = "curve.csv") -> ShearCurve | None:
    """The curve in a test's ``curve.csv`` in ``store`` (as :func:`curve_columns`); None without
    it, or when a row cannot be read as numbers (a file cut short, or not a curve)."""
    rows = store.read_rows(name)
    try:
        return None if rows is None else curve_columns(rows)
    except (KeyError, TypeError, ValueError):
        return None


def contradiction(result: Mapping, curve: ShearCurve | None, window: float) -> str | None:
    """Why a stored test's ``result.json`` cannot be what its ``curve.csv`` records; None when it can.

    A finished test is read back, not run again, so what it reads must be checked: a
    result edited by hand, a curve cut short by a full disk, or a folder copied together
    from two runs would otherwise change every answer built on it, and the folder's manifest
    (:mod:`poro2d.store.digests`) may be gone with the damage. The peak and the end value
    are read off the curve again (``window``: the test's peak window) and must agree with the
    result, both finite, and the curve must have the rows the result counts, with a finite
    displacement and shear stress in each (other columns may hold NaN: an earlier version's,
    or a ratio of a record without forces).
    """
    if curve is None:
        return "curve.csv is missing"
    x, tau = curve.shear_displacement_mm * 1e-3, curve.shear_stress_kpa
    if not (np.isfinite(x).all() and np.isfinite(tau).all()):
        return "curve.csv holds a displacement or shear stress that is not finite"
    end = result.get("end")
    stored = {
        "records": result.get("records"),
        "peak_shear_stress_kpa": result.get("peak_shear_stress_kpa"),
        "end shear_stress_kpa": end.get("shear_stress_kpa") if isinstance(end, Mapping) else None,
    }
    read = {
        "records": len(x),
        "peak_shear_stress_kpa": peak(x, tau, window).value,
        "end shear_stress_kpa": float(smooth(x, tau, window)[-1]),
    }
    for name, value in stored.items():
        if not (isinstance(value, int | float) and math.isfinite(value)):
            return f"result.json's {name} is {value!r}"
        if not math.isclose(value, read[name], rel_tol=1e-9, abs_tol=1e-9):
            return f"result.json's {name} is {value:g}, curve.csv's {read[name]:g}"
    return None


def curve_row(
    sim: Simulation, box: SplitBox, settings: ShearSettings, contacts: ContactSet,
    y_plate0: float, step0: int, rho: float,
) -> ShearRow:  # fmt: skip
    """One record of the curve from the simulation's current state.

    ``contacts`` are the simulation's current contacts, ``y_plate0`` the plate height after
    consolidation, ``step0`` the step shearing began at, ``rho`` the inertial density.
    """
    area = box.width * box.thickness
    fu = box.upper_force(sim)
    fl = box.lower_force(sim)
    pl = box.plane_force(sim, contacts)
    sigma = box.plate_force(sim) / area
    c = contacts
    return ShearRow(
        step=sim.step_count - step0,
        shear_displacement_mm=1e3 * box.shear_displacement(sim),
        shear_stress_kpa=fu[0] / area / 1e3,
        normal_stress_kpa=sigma / 1e3,
        plate_displacement_mm=1e3 * (box.plate_height(sim) - y_plate0),
        coordination_number=float(2 * np.count_nonzero(c.kind == 0) + np.count_nonzero(c.kind == 1))
        / sim.particles.n,
        lower_half_stress_kpa=-fl[0] / area / 1e3,
        plane_stress_kpa=pl.across[0] / area / 1e3,
        upper_unbalanced_kpa=pl.unbalanced[0] / area / 1e3,
        plate_friction_kpa=sim.wall_force("top")[0] / area / 1e3,
        contacts_across_plane=pl.contacts_across,
        max_unbalanced_ratio=sim.unbalanced_ratios()[0],
        inertial_number=inertial_number(settings.velocity, sigma, rho, settings.shear_zone_factor),
        plane_normal_stress_kpa=pl.across[1] / area / 1e3,
        upper_wall_friction_kpa=-sum(sim.wall_force(w)[1] for w in UPPER_SIDE_WALLS) / area / 1e3,
        **measure_fabric(c, sim.particles.n).row(),
    )


def _rel(a: np.ndarray, b: np.ndarray, mask: np.ndarray, ref: float) -> float:
    return float(np.mean(np.abs(a - b)[mask]) / ref) if ref > 0 else math.nan


def force_balance(x: np.ndarray, col: dict[str, np.ndarray], window: float) -> ForceBalance:
    """How far the upper half, the shear plane and the lower half agree, over the test.

    The first moments of shearing (one ``window``, at most half the test) are left out.
    """
    tau = col["shear_stress_kpa"]
    late = x >= min(window, 0.5 * x[-1])
    ref = float(np.mean(np.abs(tau[late])))
    return ForceBalance(
        mean_abs_upper_minus_plane_rel=_rel(tau, col["plane_stress_kpa"], late, ref),
        mean_abs_upper_minus_lower_rel=_rel(tau, col["lower_half_stress_kpa"], late, ref),
        mean_upper_kpa=float(np.mean(tau[late])),
        mean_plane_kpa=float(np.mean(col["plane_stress_kpa"][late])),
        mean_lower_kpa=float(np.mean(col["lower_half_stress_kpa"][late])),
        note="upper = force on the upper half walls; plane = contact forces across y = H/2; "
        "lower = force on the lower half walls; all over W t, means over the test after the "
        "first peak_window of displacement",
    )  # fmt: skip


def peak_passed(x: np.ndarray, x_peak: float, s: ShearSettings) -> bool:
    """The stop rule: the smoothed peak at ``x_peak`` lies ``stop_after_peak`` behind the last record."""
    return s.stop_after_peak > 0.0 and bool(x[-1] >= x_peak + s.stop_after_peak)


def ended_by(x: np.ndarray, x_peak: float, s: ShearSettings) -> str:
    """Why the test stopped where its curve ends: the peak passed or the full displacement."""
    if peak_passed(x, x_peak, s):
        return f"peak passed by {1e3 * s.stop_after_peak:g} mm (stop_after_peak)"
    return "max_displacement"


@typed_parts
@dataclass(eq=False)
class CurveSummary(TypedResult):
    """What a test's curve says: the first keys of its ``result.json``, in their order
    (:class:`~poro2d.shear.results.ShearTestResult`; the plane's share of the load at the peak,
    :func:`plane_load_at_peak`, is a later key of it)."""

    normal_stress_kpa: float
    peak_shear_stress_kpa: float
    shear_displacement_at_peak_m: float
    peak_stress_ratio: float
    peak_shear_stress_raw_kpa: float
    peak_window_m: float
    normal_stress_at_peak_kpa: float
    plate_displacement_at_peak_mm: float
    end: EndValues
    end_shear_displacement_m: float
    ended_by: str | None
    max_inertial_number: float | None
    inertial_number_ok: bool
    normal_stress_max_error_after_consolidation: float
    normal_stress_mean_error: float
    force_balance: ForceBalance


def _columns(rows: list[ShearRow]) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """The shear displacement (m) and every column of ``rows``, as arrays."""
    x = np.array([r.shear_displacement_mm for r in rows]) * 1e-3
    return x, {k: np.array([getattr(r, k) for r in rows], float) for k in CURVE_COLUMNS}


def curve_summary(rows: list[ShearRow], sigma_kpa: float, settings: ShearSettings) -> CurveSummary:
    """Peak, end values, servo error, inertial number and force balance read off the curve."""
    s = settings
    x, col = _columns(rows)
    k, xp, tp = peak(x, col["shear_stress_kpa"], s.peak_window)
    end = {}
    for name in ("shear_stress_kpa", "normal_stress_kpa", "plate_displacement_mm", "coordination_number"):
        end[name] = float(smooth(x, col[name], s.peak_window)[-1])
    sig_err = np.abs(col["normal_stress_kpa"] / sigma_kpa - 1.0)
    inertial = col["inertial_number"]
    return CurveSummary(
        normal_stress_kpa=sigma_kpa,
        peak_shear_stress_kpa=tp,
        shear_displacement_at_peak_m=xp,
        peak_stress_ratio=tp / sigma_kpa,
        peak_shear_stress_raw_kpa=float(np.max(col["shear_stress_kpa"])),
        peak_window_m=s.peak_window,
        normal_stress_at_peak_kpa=float(smooth(x, col["normal_stress_kpa"], s.peak_window)[k]),
        plate_displacement_at_peak_mm=float(col["plate_displacement_mm"][k]),
        end=EndValues(**end),
        end_shear_displacement_m=float(x[-1]),
        ended_by=ended_by(x, xp, s),
        max_inertial_number=float(np.max(inertial)),
        inertial_number_ok=bool(np.max(inertial) < s.inertial_limit),
        normal_stress_max_error_after_consolidation=float(np.max(sig_err)),
        normal_stress_mean_error=float(np.mean(sig_err)),
        force_balance=force_balance(x, col, s.peak_window),
    )


def plane_load_at_peak(rows: list[ShearRow], window: float) -> float:
    """The plane's share of the plate's load at the smoothed peak of ``rows`` (:func:`plane_load_fraction`,
    a later key of the test's ``result.json`` than those of :class:`CurveSummary`)."""
    x, col = _columns(rows)
    k = peak(x, col["shear_stress_kpa"], window)[0]
    return plane_load_fraction(x, col, k, window)


def plane_load_fraction(x: np.ndarray, col: Mapping[str, np.ndarray], k: int, window: float) -> float:
    """The part of the plate's normal stress the shear plane carries at the peak (record ``k``), smoothed.

    Below 1 when the upper side walls hold part of the load up by friction (laboratory boxes:
    0.65-0.85, Amsiejus et al. 2014); above 1 by the weight of the upper disks. NaN for a curve
    of an earlier poro2d, which did not record the plane's normal force.
    """
    plane = smooth(x, col["plane_normal_stress_kpa"], window)[k]
    plate = smooth(x, col["normal_stress_kpa"], window)[k]
    return float(plane / plate) if plate > 0 and math.isfinite(plane) else math.nan


__all__ = [
    "CURVE_COLUMNS",
    "ShearCurve",
    "ShearRow",
    "CurveSummary",
    "contradiction",
    "curve_row",
    "curve_summary",
    "plane_load_at_peak",
    "ended_by",
    "force_balance",
    "peak_passed",
]
