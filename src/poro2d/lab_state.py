"""The laboratory state in geotechnical terms: void ratio, porosity, relative density.

A soil laboratory describes a sand by its loosest and densest void ratios e_max and
e_min and a state, given as a void ratio e, a porosity n, a relative density
Dr = (e_max - e) / (e_max - e_min), or a dry density rho_d with the density of the
solids rho_s (n = 1 - rho_d / rho_s). poro2d's conversions speak porosities only; this
module turns any such description into one :class:`LabState`, whose ``n_lab``,
``n_max`` and ``n_min`` are what :func:`poro2d.porosity.convert_all` takes.

Relations used (e = n / (1 - n), n = e / (1 + e)):

* the extremes: n_max = e_max / (1 + e_max), n_min = e_min / (1 + e_min);
* a relative density: e = e_max - Dr (e_max - e_min), the definition read backwards;
* densities: n = 1 - rho_d / rho_s.

Dr is defined on void ratios, as :func:`poro2d.porosity.relative_density` defines it
(and :func:`poro2d.criterion.density.lab_relative_density` through it). When the extremes
are given the state must lie within them (0 <= Dr <= 1); the conversions themselves may
extrapolate, a description of a laboratory state may not. Every bad input raises
:class:`poro2d.errors.InputError` naming the parameter, its value and what is allowed.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from poro2d import porosity as P
from poro2d.config import check_keys
from poro2d.errors import InputError, check_range, is_number
from poro2d.record import Record

#: kg/m3, the densities of solids accepted: from light volcanic grains to the densest metal
#: (osmium, 22 590 kg/m3); 1e300 would give a porosity of 1 and an answer about nothing
SOLID_DENSITY_RANGE = (500.0, 23000.0)

#: the loosest void ratio a laboratory state may have (n = 0.990): looser than any soil (peats
#: reach about 15); beyond it the porosity rounds to 1 and a later step refuses a quantity the
#: user never typed
MAX_VOID_RATIO = 100.0

#: the ways a state can be given, as ``LabState.given`` records them (keyword -> name)
_GIVEN = {"e": "e", "n": "n", "dr": "Dr", "dry_density": "dry_density"}

#: the keys of a ``[lab]`` table (:func:`lab_state_from_table`)
TABLE_KEYS = (
    "e",
    "n",
    "dr",
    "dry_density",
    "solid_density",
    "e_max",
    "e_min",
    "n_max",
    "n_min",
    "name",
    "source",
)
_TEXT_KEYS = ("name", "source")

#: a state computed from one kind of number may land a rounding error outside extremes
#: given as the other kind (n from e against n_max); closer than this it counts as inside
_EDGE = 1e-12

_STATE_ALLOWED = "exactly one of e, n, dr, or dry_density with solid_density"


@dataclass(frozen=True)
class LabState(Record):
    """One laboratory state: its porosity, void ratio and, with the extremes, Dr.

    ``n_max``/``n_min`` are the loosest and densest laboratory porosities (None when no
    extremes were given), ``relative_density`` Dr = (e_max - e) / (e_max - e_min) (None
    without extremes) and ``given`` what the description gave: "e", "n", "Dr" or
    "dry_density". Its row (:meth:`~poro2d.record.Record.to_dict`) is every field, as JSON takes
    it (floats, None, one string).
    """

    n_lab: float
    e: float
    n_max: float | None
    n_min: float | None
    relative_density: float | None
    given: str


# ---------------------------------------------------------------------------------------
# Checks
# ---------------------------------------------------------------------------------------


def _void_ratio_value(name: str, value: Any) -> float:
    """A void ratio in [0, ``MAX_VOID_RATIO``], or InputError naming ``name``."""
    if not is_number(value) or not 0.0 <= float(value) <= MAX_VOID_RATIO:  # NaN fails too
        raise InputError(name, value, f"a finite void ratio in [0, {MAX_VOID_RATIO:g}]")
    return float(value)


def _porosity_value(name: str, value: Any) -> float:
    return check_range(name, value, 0.0, 1.0, hi_open=True)


@dataclass(frozen=True)
class _Extremes:
    """The laboratory extremes as both porosities and void ratios, and which were given."""

    n_max: float
    n_min: float
    e_max: float
    e_min: float
    as_void_ratios: bool


def _extremes(e_max: Any, e_min: Any, n_max: Any, n_min: Any) -> _Extremes | None:
    e_given = {k: v for k, v in (("e_max", e_max), ("e_min", e_min)) if v is not None}
    n_given = {k: v for k, v in (("n_max", n_max), ("n_min", n_min)) if v is not None}
    if e_given and n_given:
        key = next(iter(n_given))
        raise InputError(
            key,
            n_given[key],
            "either the void ratios e_max and e_min or the porosities n_max and n_min, not both",
            f"{' and '.join(e_given)} given as well",
        )
    for given, pair, what in (
        (e_given, ("e_max", "e_min"), "void ratio"),
        (n_given, ("n_max", "n_min"), "porosity"),
    ):
        if len(given) == 1:
            (present,) = given
            missing = pair[1] if present == pair[0] else pair[0]
            raise InputError(
                missing, None, f"a {what} given together with {present}", f"{present} given without {missing}"
            )
    if e_given:
        hi = _void_ratio_value("e_max", e_max)
        lo = _void_ratio_value("e_min", e_min)
        if not hi > lo:
            raise InputError("e_max", e_max, f"greater than e_min = {lo:g}", "e_max is the loosest state")
        return _Extremes(
            float(P.porosity_from_void_ratio(hi)), float(P.porosity_from_void_ratio(lo)), hi, lo, True
        )
    if n_given:
        hi = _porosity_value("n_max", n_max)
        lo = _porosity_value("n_min", n_min)
        if not hi > lo:
            raise InputError("n_max", n_max, f"greater than n_min = {lo:g}", "n_max is the loosest state")
        return _Extremes(hi, lo, float(P.void_ratio(hi)), float(P.void_ratio(lo)), False)
    return None


def lab_extremes(
    *, e_max: Any = None, e_min: Any = None, n_max: Any = None, n_min: Any = None
) -> tuple[float, float] | None:
    """The laboratory extremes as porosities ``(n_max, n_min)``, from either pair.

    ``e_max``/``e_min`` (void ratios >= 0) or ``n_max``/``n_min`` (porosities in [0, 1)),
    loosest above densest; None when neither pair is given. A pair mixed from both kinds,
    half a pair, negative or non-finite values and e_min >= e_max are refused.
    """
    ex = _extremes(e_max, e_min, n_max, n_min)
    return None if ex is None else (ex.n_max, ex.n_min)


# ---------------------------------------------------------------------------------------
# The state
# ---------------------------------------------------------------------------------------


def _dr_of(e: float, ex: _Extremes) -> float:
    return (ex.e_max - e) / (ex.e_max - ex.e_min)


def _check_within(
    name: str, value: float, n: float, e: float, ex: _Extremes, solid_density: float | None
) -> None:
    """Refuse a state outside the extremes, in the terms of the quantity given."""
    if ex.as_void_ratios:
        inside = ex.e_min - _EDGE <= e <= ex.e_max + _EDGE
    else:
        inside = ex.n_min - _EDGE <= n <= ex.n_max + _EDGE
    if inside:
        return
    ends = (
        f"e_min = {ex.e_min:g}, e_max = {ex.e_max:g}"
        if ex.as_void_ratios
        else f"n_min = {ex.n_min:g}, n_max = {ex.n_max:g}"
    )
    if name == "e":
        allowed = f"[{ex.e_min:.6g}, {ex.e_max:.6g}], between the laboratory extremes ({ends})"
    elif name == "n":
        allowed = f"[{ex.n_min:.6g}, {ex.n_max:.6g}], between the laboratory extremes ({ends})"
    else:
        lo, hi = solid_density * (1.0 - ex.n_max), solid_density * (1.0 - ex.n_min)
        allowed = (
            f"[{lo:.6g}, {hi:.6g}] kg/m3 with solid_density = {solid_density:g}, "
            f"between the laboratory extremes ({ends})"
        )
    raise InputError(
        name, value, allowed, f"the state would have Dr = {_dr_of(e, ex):.4g}; Dr must lie in [0, 1]"
    )


def _which_state(e: Any, n: Any, dr: Any, dry_density: Any, solid_density: Any) -> str:
    """The one keyword that gives the state, or InputError."""
    given = {k: v for k, v in (("e", e), ("n", n), ("dr", dr), ("dry_density", dry_density)) if v is not None}
    if solid_density is not None and dry_density is None:
        raise InputError(
            "solid_density", solid_density, "only together with dry_density", "no dry_density given"
        )
    if not given:
        raise InputError("state", None, _STATE_ALLOWED, "no state given")
    if len(given) > 1:
        first, *rest = given
        key = rest[0]
        raise InputError(key, given[key], _STATE_ALLOWED, f"{first} = {given[first]!r} given as well")
    return next(iter(given))


def lab_state(
    *,
    e: Any = None,
    n: Any = None,
    dr: Any = None,
    dry_density: Any = None,
    solid_density: Any = None,
    e_max: Any = None,
    e_min: Any = None,
    n_max: Any = None,
    n_min: Any = None,
) -> LabState:
    """The laboratory state from a geotechnical description.

    Exactly one of ``e`` (void ratio >= 0), ``n`` (porosity in [0, 1)), ``dr`` (relative
    density in [0, 1]; needs the extremes) or ``dry_density`` (kg/m3, with
    ``solid_density`` in :data:`SOLID_DENSITY_RANGE`), and optionally the extremes as
    ``e_max``/``e_min`` or ``n_max``/``n_min`` (:func:`lab_extremes`). With extremes the
    state must lie within them; the refusal names the value and the range.

    Toyoura-like sand: ``lab_state(e=0.7, e_max=0.977, e_min=0.597)`` has n = 0.41176
    and Dr = 0.7289.
    """
    key = _which_state(e, n, dr, dry_density, solid_density)
    ex = _extremes(e_max, e_min, n_max, n_min)
    value: Any = {"e": e, "n": n, "dr": dr, "dry_density": dry_density}[key]
    if key == "e":
        ev = _void_ratio_value("e", e)
        nv = float(P.porosity_from_void_ratio(ev))
    elif key == "n":
        nv = _porosity_value("n", n)
        ev = float(P.void_ratio(nv))
    elif key == "dry_density":
        if solid_density is None:
            lo, hi = SOLID_DENSITY_RANGE
            raise InputError(
                "solid_density",
                None,
                f"[{lo:g}, {hi:g}] kg/m3, together with dry_density",
                "dry_density given without it",
            )
        rho_s = check_range("solid_density", solid_density, *SOLID_DENSITY_RANGE)
        loosest = rho_s / (1.0 + MAX_VOID_RATIO)
        if not is_number(dry_density) or not loosest <= float(dry_density) <= rho_s:
            raise InputError(
                "dry_density", dry_density, f"[{loosest:.6g}, {rho_s:g}] kg/m3",
                f"positive and at most the solid density, of a void ratio of at most {MAX_VOID_RATIO:g}",
            )  # fmt: skip
        nv = float(P.porosity_from_densities(float(dry_density), rho_s))
        ev = float(P.void_ratio(nv))
    else:
        if ex is None:
            raise InputError(
                "dr", dr, "a relative density with the extremes e_max and e_min (or n_max and n_min)",
                "Dr is defined between the loosest and the densest state",
            )  # fmt: skip
        if not is_number(dr) or not 0.0 <= float(dr) <= 1.0:
            raise InputError("dr", dr, "[0, 1]", "Dr = 1 is the densest state, Dr = 0 the loosest")
        d = float(dr)
        ev = ex.e_max - d * (ex.e_max - ex.e_min)
        nv = float(P.porosity_from_void_ratio(ev))
        return LabState(nv, ev, ex.n_max, ex.n_min, d, _GIVEN[key])
    if ex is None:
        return LabState(nv, ev, None, None, None, _GIVEN[key])
    _check_within(key, value, nv, ev, ex, None if key != "dry_density" else float(solid_density))
    return LabState(nv, ev, ex.n_max, ex.n_min, _dr_of(ev, ex), _GIVEN[key])


def lab_state_from_table(table: Mapping) -> LabState:
    """The state of a TOML ``[lab]`` table: the keywords of :func:`lab_state` as keys.

    Allowed keys: :data:`TABLE_KEYS`; ``name`` and ``source`` are strings describing the
    soil, checked and not used here. An unknown key is refused naming it and the allowed
    ones; errors name the key as ``lab.<key>``.
    """
    if not isinstance(table, Mapping):
        raise InputError("lab", table, "a table of key = value pairs")
    table = dict(table)
    check_keys("lab", table, TABLE_KEYS)
    for key in _TEXT_KEYS:
        if key in table and not isinstance(table[key], str):
            raise InputError(f"lab.{key}", table[key], "a string")
    numbers = {k: v for k, v in table.items() if k not in _TEXT_KEYS}
    try:
        return lab_state(**numbers)
    except InputError as exc:
        name = "lab" if exc.parameter == "state" else f"lab.{exc.parameter}"
        raise InputError(name, exc.value, exc.allowed, exc.hint) from None
