"""3D (laboratory) to 2D porosity conversions: Eqs. 1-12 of Wang, Jacobs & Ziegler.

Source: "A new suggestion for determining 2D porosities in DEM studies" (Wang, Jacobs and
Ziegler, RWTH Aachen), section 2 (the six established approaches, Eqs. 1-11, and the
LIM_2D-3D line of section 2.2) and section 3 (the parabola, Eq. 12).

Every conversion is a plain vectorised function: it accepts a float or a NumPy array of
laboratory porosities and returns a float or an array of the same shape. Porosities must
lie in [0, 1) and must not be NaN; laboratory extremes must satisfy n_max > n_min.
Anything else raises :class:`poro2d.errors.InputError`.

The functions never clip. A laboratory porosity outside [n_min, n_max] is *computed*
(the paper's Fig. 1 extrapolates on purpose), and negative 2D porosities are returned as
they are. :func:`convert_all` runs every method for one laboratory porosity and attaches
the flags ``"negative"``, ``"extrapolated"``, ``"decreasing"``, ``"undefined"`` together
with a warning text, so nothing is reported as a silent number.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from poro2d.errors import InputError, check_range

ArrayLike = float | np.ndarray

# ---------------------------------------------------------------------------------------
# Lattice porosities of mono-sized disks (2D) and spheres (3D)
# ---------------------------------------------------------------------------------------

#: Square packing of equal disks: 1 - pi/4 (loosest regular 2D packing).
SQUARE_2D = 1.0 - math.pi / 4.0
#: Hexagonal packing of equal disks: 1 - pi/(2 sqrt 3) (densest 2D packing).
HEXAGONAL_2D = 1.0 - math.pi / (2.0 * math.sqrt(3.0))
#: Simple cubic packing of equal spheres: 1 - pi/6 (loosest regular 3D packing).
SIMPLE_CUBIC_3D = 1.0 - math.pi / 6.0
#: Face centred cubic packing of equal spheres: 1 - pi/(3 sqrt 2) (densest 3D packing).
FCC_3D = 1.0 - math.pi / (3.0 * math.sqrt(2.0))

#: The 2D extremes as printed below Eq. 6 of the paper (rounded lattice values).
N2D_MAX_PRINTED = 0.2146
N2D_MIN_PRINTED = 0.0931

#: The paper's sand (section 2.2 and section 4): n_lab,max, n_lab,min, test porosity.
PAPER_N_MAX = 0.4571
PAPER_N_MIN = 0.3253
PAPER_N_LAB = 0.3434
#: Dry density 1.74 g/cm3 and solid density 2650 kg/m3 (Table 1) of the paper's sand.
PAPER_DRY_DENSITY = 1740.0
PAPER_SOLID_DENSITY = 2650.0

_SQRT_PI_SQRT3 = math.sqrt(math.pi * math.sqrt(3.0))

NU_READINGS = ("printed", "solid_fraction")


# ---------------------------------------------------------------------------------------
# Validation helpers
# ---------------------------------------------------------------------------------------


def _as_array(name: str, value: Any) -> np.ndarray:
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InputError(name, value, "a number or an array of numbers") from None
    return arr


def _check_porosity(name: str, value: Any) -> np.ndarray:
    """Return ``value`` as a float array; raise InputError unless every entry is in [0, 1)."""
    arr = _as_array(name, value)
    bad = ~((arr >= 0.0) & (arr < 1.0))  # NaN compares False, so it is caught here
    if np.any(bad):
        first = float(arr[bad].flat[0])
        check_range(name, first, 0.0, 1.0, hi_open=True)
    return arr


def _check_extremes(n_max: Any, n_min: Any) -> tuple[float, float]:
    hi = float(_check_porosity("n_max", n_max)) if np.ndim(n_max) == 0 else None
    lo = float(_check_porosity("n_min", n_min)) if np.ndim(n_min) == 0 else None
    if hi is None:
        raise InputError("n_max", n_max, "a single number in [0, 1)")
    if lo is None:
        raise InputError("n_min", n_min, "a single number in [0, 1)")
    if not hi > lo:
        raise InputError("n_max", hi, f"greater than n_min = {lo}")
    return hi, lo


def _out(arr: np.ndarray, like: Any) -> ArrayLike:
    """Return a float for scalar input, an array of the input's shape otherwise."""
    if np.ndim(like) == 0:
        return float(arr)
    return arr


# ---------------------------------------------------------------------------------------
# Helpers: void ratio, relative density, densities
# ---------------------------------------------------------------------------------------


def void_ratio(n: ArrayLike) -> ArrayLike:
    """Void ratio e = n / (1 - n) of a porosity n in [0, 1)."""
    arr = _check_porosity("n", n)
    return _out(arr / (1.0 - arr), n)


def porosity_from_void_ratio(e: ArrayLike) -> ArrayLike:
    """Porosity n = e / (1 + e) of a void ratio e >= 0."""
    arr = _as_array("e", e)
    bad = ~(arr >= 0.0) | ~np.isfinite(arr)
    if np.any(bad):
        check_range("e", float(arr[bad].flat[0]), 0.0, None)
        raise InputError("e", float(arr[bad].flat[0]), "[0, inf)")
    return _out(arr / (1.0 + arr), e)


def relative_density(n: ArrayLike, n_max: float, n_min: float) -> ArrayLike:
    """Relative density D_r = (e_max - e) / (e_max - e_min), from void ratios.

    Used by the Combination Method (Eq. 5, Zhang 2007). e = n / (1 - n); e_max and e_min
    belong to n_max and n_min. D_r is 1 at n_min, 0 at n_max, and lies outside [0, 1]
    when n is outside [n_min, n_max] (no clipping). The paper's sand gives
    D_r(0.3434) = 0.886, printed as 0.89.
    """
    hi, lo = _check_extremes(n_max, n_min)
    arr = _check_porosity("n_lab", n)
    e = arr / (1.0 - arr)
    e_max = hi / (1.0 - hi)
    e_min = lo / (1.0 - lo)
    return _out((e_max - e) / (e_max - e_min), n)


def porosity_from_densities(dry_density: ArrayLike, solid_density: ArrayLike) -> ArrayLike:
    """Porosity n = 1 - rho_d / rho_s from dry density and density of the solids (kg/m3).

    The paper's sand: 1 - 1740 / 2650 = 0.34340 (printed as 0.3434). Both densities must
    be positive and rho_d <= rho_s, so that n lies in [0, 1).
    """
    rd = _as_array("dry_density", dry_density)
    rs = _as_array("solid_density", solid_density)
    bad_s = ~(rs > 0.0) | ~np.isfinite(rs)
    if np.any(bad_s):
        raise InputError("solid_density", float(rs[bad_s].flat[0]), "(0, inf) kg/m3")
    rd_b, rs_b = np.broadcast_arrays(rd, rs)
    bad_d = ~((rd_b > 0.0) & (rd_b <= rs_b))
    if np.any(bad_d):
        i = np.flatnonzero(bad_d)[0]
        raise InputError(
            "dry_density",
            float(rd_b.flat[i]),
            f"(0, {float(rs_b.flat[i])}] kg/m3, i.e. positive and at most the solid density",
        )
    res = 1.0 - rd_b / rs_b
    return _out(res, rd_b if np.ndim(dry_density) or np.ndim(solid_density) else 0.0)


# ---------------------------------------------------------------------------------------
# The conversions
# ---------------------------------------------------------------------------------------


def densest_state(n_lab: ArrayLike) -> ArrayLike:
    """Densest State Method, Eq. (1) (Hoomans et al. 1996).

    n2D = 1 - [ sqrt(pi sqrt 3) / 2 * (1 - n3D) ]^(2/3)

    Matches the densest 2D packing (hexagonal) with the densest 3D packing (FCC) of
    mono-sized particles of equal diameter: it maps FCC_3D exactly onto HEXAGONAL_2D.
    Negative for n_lab < 1 - 2 / sqrt(pi sqrt 3) = 0.1426.
    """
    n = _check_porosity("n_lab", n_lab)
    return _out(1.0 - (_SQRT_PI_SQRT3 / 2.0 * (1.0 - n)) ** (2.0 / 3.0), n_lab)


def nu_factor(n_min: float, nu_reading: str = "printed") -> float:
    """The empirical factor nu of Eq. (2) (van Wachem et al. 2001).

    ``"printed"``: nu = n_lab,min / n_3D,min, exactly as printed below Eq. (2), with
    n_3D,min = FCC porosity 1 - pi/(3 sqrt 2) = 0.2595.
    ``"solid_fraction"``: nu = (1 - n_lab,min) / (1 - n_3D,min), the ratio of the maximum
    experimental solids packing to the theoretical one, which is how van Wachem et al.
    describe the parameter ("maximum experimental solids packing").
    """
    if nu_reading not in NU_READINGS:
        raise InputError("nu_reading", nu_reading, " or ".join(NU_READINGS))
    lo = float(_check_porosity("n_min", n_min))
    if nu_reading == "printed":
        if lo == 0.0:
            raise InputError("n_min", lo, "(0, 1) when nu_reading = 'printed' (nu = n_min / n_FCC)")
        return lo / FCC_3D
    return (1.0 - lo) / (1.0 - FCC_3D)


def densest_state_modified(n_lab: ArrayLike, n_min: float, nu_reading: str = "printed") -> ArrayLike:
    """Modified Densest State Method, Eq. (2) (van Wachem et al. 2001).

    n2D = 1 - [ sqrt(pi sqrt 3) / (2 nu) * (1 - n3D) ]^(2/3)

    Eq. (1) with an empirical factor nu that carries the laboratory's densest state
    (see :func:`nu_factor` for the two readings of nu; ``nu_reading`` chooses one, there
    is no silent default beyond the printed formula). With nu = 1 it is Eq. (1).
    """
    n = _check_porosity("n_lab", n_lab)
    nu = nu_factor(n_min, nu_reading)
    return _out(1.0 - (_SQRT_PI_SQRT3 / (2.0 * nu) * (1.0 - n)) ** (2.0 / 3.0), n_lab)


def loosest_state(n_lab: ArrayLike) -> ArrayLike:
    """Loosest State Method, Eq. (3) (Helland et al. 2005).

    n2D = 3/2 n3D - 1/2

    Matches the square 2D packing with the simple cubic 3D packing (pseudo-3D: bed depth
    equal to the particle diameter). Maps SIMPLE_CUBIC_3D exactly onto SQUARE_2D.
    Negative for n_lab < 1/3.
    """
    n = _check_porosity("n_lab", n_lab)
    return _out(1.5 * n - 0.5, n_lab)


def interval_mapping(n_lab: ArrayLike) -> ArrayLike:
    """Interval Mapping Method, Eq. (4) (Ouyang and Li 1999).

    n2D = 1 - [ sqrt(pi sqrt 3) / sqrt 2 * (1 - n3D) ]^(2/3)

    Verified by its authors on a 2D hexagonal lattice against a 3D hexagonal packing of
    mono-sized spheres. Negative for n_lab < 1 - sqrt 2 / sqrt(pi sqrt 3) = 0.3937.
    """
    n = _check_porosity("n_lab", n_lab)
    return _out(1.0 - (_SQRT_PI_SQRT3 / math.sqrt(2.0) * (1.0 - n)) ** (2.0 / 3.0), n_lab)


def combination_xi(n_lab: ArrayLike, n_max: float, n_min: float) -> ArrayLike:
    """xi of Eq. (5): sqrt2/sqrt(pi sqrt3) + D_r (2/sqrt(pi sqrt3) - sqrt2/sqrt(pi sqrt3))."""
    dr = np.asarray(relative_density(n_lab, n_max, n_min))
    a = math.sqrt(2.0) / _SQRT_PI_SQRT3
    b = 2.0 / _SQRT_PI_SQRT3
    return _out(a + dr * (b - a), n_lab)


def combination(n_lab: ArrayLike, n_max: float, n_min: float) -> ArrayLike:
    """Combination Method, Eq. (5) (Zhang 2007).

    n2D = 1 - ((1 - n_lab) / xi)^(2/3),
    xi = sqrt2 / sqrt(pi sqrt3) + D_r (2 / sqrt(pi sqrt3) - sqrt2 / sqrt(pi sqrt3)),
    D_r = (e_max - e) / (e_max - e_min) with void ratios e = n / (1 - n).

    D_r = 0 gives the Interval Mapping Method (Eq. 4), D_r = 1 the Densest State Method
    (Eq. 1). Between them it blends the two by relative density, which makes n2D
    *decrease* with n_lab for ordinary sands (the paper's criticism). Where an
    extrapolated D_r drives xi to zero or below (very loose n_lab far above n_max) the
    formula has no real value and NaN is returned; :func:`convert_all` flags it.
    """
    n = _check_porosity("n_lab", n_lab)
    xi = np.asarray(combination_xi(n, n_max, n_min), dtype=float)
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = np.where(xi > 0.0, (1.0 - n) / np.where(xi > 0.0, xi, 1.0), np.nan)
        res = 1.0 - ratio ** (2.0 / 3.0)
    return _out(res, n_lab)


def combination_slope_sign(n_lab: ArrayLike, n_max: float, n_min: float) -> ArrayLike:
    """Sign of d n2D / d n_lab of Eq. (5) (analytic; -1 where the method decreases).

    With u = 1 - n and xi(u) linear in 1/u, d n2D/d n has the sign of
    xi - u dxi/du = a + (b - a) (e_max + 1 - 2/u) / (e_max - e_min).
    """
    n = _check_porosity("n_lab", n_lab)
    hi, lo = _check_extremes(n_max, n_min)
    a = math.sqrt(2.0) / _SQRT_PI_SQRT3
    b = 2.0 / _SQRT_PI_SQRT3
    e_max = hi / (1.0 - hi)
    e_min = lo / (1.0 - lo)
    g = a + (b - a) * (e_max + 1.0 - 2.0 / (1.0 - n)) / (e_max - e_min)
    return _out(np.sign(g), n_lab)


def _n2d_extremes(n2d_max: float | None, n2d_min: float | None, lattice_exact: bool) -> tuple[float, float]:
    if lattice_exact:
        hi, lo = SQUARE_2D, HEXAGONAL_2D
    else:
        hi, lo = N2D_MAX_PRINTED, N2D_MIN_PRINTED
    if n2d_max is not None:
        hi = float(_check_porosity("n2d_max", n2d_max))
    if n2d_min is not None:
        lo = float(_check_porosity("n2d_min", n2d_min))
    if not hi > lo:
        raise InputError("n2d_max", hi, f"greater than n2d_min = {lo}")
    return hi, lo


def degree_of_density(n_lab: ArrayLike, n_max: float, n_min: float) -> ArrayLike:
    """D = (n_lab,max - n_lab) / (n_lab,max - n_lab,min), Eq. (6) (porosity-based)."""
    hi, lo = _check_extremes(n_max, n_min)
    n = _check_porosity("n_lab", n_lab)
    return _out((hi - n) / (hi - lo), n_lab)


def _degree_and_2d_extremes(
    n_lab: ArrayLike,
    n_max: float,
    n_min: float,
    *,
    lattice_exact: bool = False,
    n2d_max: float | None = None,
    n2d_min: float | None = None,
) -> tuple[np.ndarray, float, float]:
    """D of Eq. (6) and the 2D extremes (n2D,max, n2D,min) that Eqs. (7)-(11) interpolate between:
    the printed ones, the lattice values with ``lattice_exact``, or ``n2d_max``/``n2d_min``."""
    d = np.asarray(degree_of_density(n_lab, n_max, n_min))
    return d, *_n2d_extremes(n2d_max, n2d_min, lattice_exact)


def lim_lab(n_lab: ArrayLike, n_max: float, n_min: float, **extremes_2d: Any) -> ArrayLike:
    """Linear Interpolation Method LIM_2D-Lab, Eqs. (6)-(7) (Giese 2002; Hainbuechner et al. 2002).

    n2D = n2D,max - D (n2D,max - n2D,min),  D = (n_lab,max - n_lab) / (n_lab,max - n_lab,min)

    Same degree of density in 2D and in the laboratory. The 2D extremes (keywords) default to
    the printed values 0.2146 and 0.0931; ``lattice_exact=True`` uses 1 - pi/4 and
    1 - pi/(2 sqrt 3) (they differ from the printed ones by less than 5e-6), explicit
    ``n2d_max``/``n2d_min`` override both. The paper's sand gives 0.11 at n_lab = 0.3434.
    """
    d, hi2, lo2 = _degree_and_2d_extremes(n_lab, n_max, n_min, **extremes_2d)
    return _out(hi2 - d * (hi2 - lo2), n_lab)


def lim_3d(n_lab: ArrayLike) -> ArrayLike:
    """LIM_2D-3D, section 2.2 and Fig. 2 of the paper.

    The straight line through (simple cubic 3D porosity, square 2D porosity) =
    (0.4764, 0.2146) and (FCC 3D porosity, hexagonal 2D porosity) = (0.2595, 0.0931):

    n2D = n_hex + (n_lab - n_FCC) (n_sq - n_hex) / (n_SC - n_FCC)   (slope 0.5602)

    Independent of the laboratory extremes. At n_lab = 0.3434 it gives 0.1401 (the
    paper: 0.14). Outside [n_FCC, n_SC] the line is extrapolated.
    """
    n = _check_porosity("n_lab", n_lab)
    slope = (SQUARE_2D - HEXAGONAL_2D) / (SIMPLE_CUBIC_3D - FCC_3D)
    return _out(HEXAGONAL_2D + (n - FCC_3D) * slope, n_lab)


def quasi_3d_extremes(n2d_max: float, n2d_min: float) -> tuple[float, float]:
    """n'3D,max = 1/3 + 2/3 n2D,max and n'3D,min = 1/3 + 2/3 n2D,min, Eqs. (8)-(9)."""
    return 1.0 / 3.0 + 2.0 / 3.0 * n2d_max, 1.0 / 3.0 + 2.0 / 3.0 * n2d_min


def quasi_3d(n_lab: ArrayLike, n_max: float, n_min: float, **extremes_2d: Any) -> ArrayLike:
    """Quasi 3D Porosity Method, Eqs. (8)-(11) (Bezuijen and van den Berg 2002).

    n'3D,max = 1/3 + 2/3 n2D,max                                   (8)
    n'3D,min = 1/3 + 2/3 n2D,min                                   (9)
    n'3D = n'3D,max - D (n'3D,max - n'3D,min), D as in Eq. (6)     (10)
    n2D = 3/2 n'3D - 1/2                                           (11)

    Assumes disks whose thickness equals their diameter (a disk is then a cylinder that
    holds the sphere). Eq. (11) is the inverse of Eqs. (8)-(9), so with the same 2D
    extremes the result equals LIM_2D-Lab (Eq. 7) identically; this function evaluates the
    four equations as printed. The 2D extremes are chosen as in :func:`lim_lab`.
    """
    d, hi2, lo2 = _degree_and_2d_extremes(n_lab, n_max, n_min, **extremes_2d)
    q_max, q_min = quasi_3d_extremes(hi2, lo2)
    q = q_max - d * (q_max - q_min)
    return _out(1.5 * q - 0.5, n_lab)


def parabolic(n_lab: ArrayLike) -> ArrayLike:
    """The paper's parabola, Eq. (12) (Wang, Jacobs and Ziegler, section 3).

    n2D = 0.42 n_lab^2 + 0.25 n_lab

    Built from three points: the origin and the two ends of LIM_2D-3D, (n_FCC, n_hex) and
    (n_SC, n_sq). The rounded coefficients pass within 7e-5 of the FCC point and 1.8e-4 of
    the simple cubic point (the exact parabola is 0.4229 n^2 + 0.2490 n). An initial
    guess, to be refined by the paper's criterion (Fig. 3). 0.3434 -> 0.1354.
    """
    n = _check_porosity("n_lab", n_lab)
    return _out(0.42 * n * n + 0.25 * n, n_lab)


# ---------------------------------------------------------------------------------------
# Registry and convert_all
# ---------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Method:
    """One conversion method: identity, provenance and what it needs.

    ``func(n_lab, n_max, n_min, options)`` evaluates the method (arrays or floats);
    ``needs`` lists the laboratory extremes it requires; ``interpolates`` marks methods
    built on D or D_r, for which n_lab outside [n_min, n_max] is an extrapolation.
    """

    id: str
    name: str
    equation: str
    source: str
    needs: tuple[str, ...]
    interpolates: bool
    func: Callable[[ArrayLike, Any, Any, dict], ArrayLike] = field(repr=False, compare=False)

    @property
    def needs_extremes(self) -> bool:
        return bool(self.needs)


def _exact(o: dict) -> bool:
    return bool(o.get("lattice_exact", False))


def _nu_reading(o: dict) -> str:
    return o.get("nu_reading", "printed")


#: Each method's id, name, equation, source, the extremes it needs and whether it interpolates,
#: in the paper's order (section 2.1, then LIM_2D-3D, then Eq. 12).
_BOTH, _MIN = ("n_max", "n_min"), ("n_min",)
_METHOD_ROWS = (
    ("densest_state", "Densest State", "Eq. 1", "Hoomans et al. 1996", (), False),
    ("densest_state_modified", "Densest State (modified)", "Eq. 2", "van Wachem et al. 2001", _MIN, False),
    ("loosest_state", "Loosest State", "Eq. 3", "Helland et al. 2005", (), False),
    ("interval_mapping", "Interval Mapping", "Eq. 4", "Ouyang and Li 1999", (), False),
    ("combination", "Combination", "Eq. 5", "Zhang 2007", _BOTH, True),
    ("lim_lab", "LIM 2D-Lab", "Eqs. 6-7", "Giese 2002; Hainbuechner et al. 2002", _BOTH, True),
    ("lim_3d", "LIM 2D-3D", "Sec. 2.2", "Wang, Jacobs and Ziegler (Fig. 2)", (), False),
    ("quasi_3d", "Quasi 3D Porosity", "Eqs. 8-11", "Bezuijen and van den Berg 2002", _BOTH, True),
    ("parabolic", "Parabola", "Eq. 12", "Wang, Jacobs and Ziegler", (), False),
)
#: each method's evaluation ``func(n_lab, n_max, n_min, options)``, by id
_METHOD_FUNCS: dict[str, Callable[[ArrayLike, Any, Any, dict], ArrayLike]] = {
    "densest_state": lambda n, hi, lo, o: densest_state(n),
    "densest_state_modified": lambda n, hi, lo, o: densest_state_modified(n, lo, _nu_reading(o)),
    "loosest_state": lambda n, hi, lo, o: loosest_state(n),
    "interval_mapping": lambda n, hi, lo, o: interval_mapping(n),
    "combination": lambda n, hi, lo, o: combination(n, hi, lo),
    "lim_lab": lambda n, hi, lo, o: lim_lab(n, hi, lo, lattice_exact=_exact(o)),
    "lim_3d": lambda n, hi, lo, o: lim_3d(n),
    "quasi_3d": lambda n, hi, lo, o: quasi_3d(n, hi, lo, lattice_exact=_exact(o)),
    "parabolic": lambda n, hi, lo, o: parabolic(n),
}
#: All methods, in the paper's order (section 2.1, then LIM_2D-3D, then Eq. 12).
METHODS: dict[str, Method] = {row[0]: Method(*row, func=_METHOD_FUNCS[row[0]]) for row in _METHOD_ROWS}


@dataclass
class MethodResult:
    """The outcome of one method for one laboratory porosity."""

    id: str
    name: str
    equation: str
    source: str
    value: float | None
    skipped: str | None = None
    flags: list[str] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    details: dict[str, Any] = field(default_factory=dict)


@dataclass
class Conversion:
    """Every method applied to one laboratory porosity (see :func:`convert_all`)."""

    n_lab: float
    n_max: float | None
    n_min: float | None
    options: dict[str, Any]
    results: dict[str, MethodResult]
    notes: list[str] = field(default_factory=list)

    @property
    def warnings(self) -> list[str]:
        return [w for r in self.results.values() for w in r.warnings]


def _conversion_options(options: dict) -> tuple[str, bool]:
    """(nu_reading, lattice_exact) of :func:`convert_all`; unknown options are errors."""
    unknown = set(options) - {"nu_reading", "lattice_exact"}
    if unknown:
        name = sorted(unknown)[0]
        raise InputError(name, options[name], "options nu_reading, lattice_exact")
    nu_reading = options.get("nu_reading", "printed")
    if nu_reading not in NU_READINGS:
        raise InputError("nu_reading", nu_reading, " or ".join(NU_READINGS))
    return nu_reading, bool(options.get("lattice_exact", False))


def _method_result(m, n: float, hi, lo, nu_reading: str, lattice_exact: bool) -> MethodResult:
    """One method's value at ``n`` with its details, flags and warnings (see :func:`convert_all`)."""
    r = MethodResult(m.id, m.name, m.equation, m.source, value=None)
    given = {"n_max": hi, "n_min": lo}
    if any(given[k] is None for k in m.needs):
        r.skipped = "needs " + " and ".join(m.needs)
        return r
    val = float(m.func(n, hi, lo, {"nu_reading": nu_reading, "lattice_exact": lattice_exact}))
    if m.id == "densest_state_modified":
        nu = nu_factor(lo, nu_reading)
        r.details.update(nu_reading=nu_reading, nu=nu, n_3d_min=FCC_3D)
        other = "solid_fraction" if nu_reading == "printed" else "printed"
        other_val = float(densest_state_modified(n, lo, other))
        r.details["other_reading"] = {"nu_reading": other, "n2d": other_val}
        r.flags.append(f"nu={nu_reading}")
    if m.interpolates:
        r.details["D_r" if m.id == "combination" else "D"] = float(
            relative_density(n, hi, lo) if m.id == "combination" else degree_of_density(n, hi, lo)
        )
        if not lo <= n <= hi:
            r.flags.append("extrapolated")
            r.warnings.append(
                f"{m.id}: n_lab = {n:g} lies outside [n_min, n_max] = [{lo:g}, {hi:g}]; "
                "the value is an extrapolation of the method"
            )
    if m.id in ("lim_lab", "quasi_3d"):
        hi2, lo2 = _n2d_extremes(None, None, lattice_exact)
        r.details.update(n2d_max=hi2, n2d_min=lo2, lattice_exact=lattice_exact)
    if m.id == "lim_3d" and not FCC_3D <= n <= SIMPLE_CUBIC_3D:
        r.flags.append("beyond_lattice")
        r.warnings.append(
            f"lim_3d: n_lab = {n:g} lies outside the lattice segment "
            f"[{FCC_3D:.4f}, {SIMPLE_CUBIC_3D:.4f}] (FCC to simple cubic); extrapolated line"
        )
    if m.id == "combination":
        r.details["xi"] = float(combination_xi(n, hi, lo))
        if float(combination_slope_sign(n, hi, lo)) < 0:
            r.flags.append("decreasing")
    if math.isnan(val):
        r.flags.append("undefined")
        r.skipped = "no real value (xi <= 0 for this extrapolated relative density)"
        r.warnings.append(f"{m.id}: no real 2D porosity at n_lab = {n:g} (xi <= 0)")
        return r
    r.value = val
    if val < 0.0:
        r.flags.append("negative")
        r.warnings.append(
            f"{m.id}: negative 2D porosity {val:.4f} at n_lab = {n:g} "
            "(physically impossible; reported, not clipped)"
        )
    return r


def convert_all(
    n_lab: float,
    n_max: float | None = None,
    n_min: float | None = None,
    **options: Any,
) -> Conversion:
    """Run every method of :data:`METHODS` for one laboratory porosity.

    Options: ``nu_reading`` ("printed" or "solid_fraction", for Eq. 2; recorded in the
    result), ``lattice_exact`` (bool, for Eqs. 7 and 8-11).

    Methods whose laboratory extremes are missing are skipped (``value=None`` and the
    reason in ``skipped``). Flags: ``"negative"`` (n2D < 0, reported as is),
    ``"extrapolated"`` (n_lab outside [n_min, n_max] for methods that interpolate between
    the laboratory extremes; a warning text is added too), ``"decreasing"`` (the
    Combination Method falls with n_lab at this point), ``"beyond_lattice"`` (LIM_2D-3D
    outside [n_FCC, n_SC]), ``"undefined"`` (no real value, e.g. xi <= 0 in Eq. 5).
    """
    nu_reading, lattice_exact = _conversion_options(options)
    if np.ndim(n_lab) != 0:
        raise InputError("n_lab", n_lab, "a single number in [0, 1) (call once per value)")
    n = float(_check_porosity("n_lab", n_lab))
    hi = None if n_max is None else float(_check_porosity("n_max", n_max))
    lo = None if n_min is None else float(_check_porosity("n_min", n_min))
    if hi is not None and lo is not None:
        _check_extremes(hi, lo)
    results = {m.id: _method_result(m, n, hi, lo, nu_reading, lattice_exact) for m in METHODS.values()}
    notes: list[str] = []
    if lo is not None:
        notes.append(
            f"Eq. 2 uses nu_reading = {nu_reading!r} "
            f"(nu = {nu_factor(lo, nu_reading):.4f}; n_3D,min = FCC porosity {FCC_3D:.4f})"
        )
    if hi is not None and lo is not None:
        notes.append("quasi_3d (Eqs. 8-11) equals lim_lab (Eq. 7) identically: Eq. 11 inverts Eqs. 8-9")
    notes.append(
        "2D extremes for Eqs. 7-11: "
        + ("lattice exact (1 - pi/4, 1 - pi/(2 sqrt 3))" if lattice_exact else "as printed (0.2146, 0.0931)")
    )
    return Conversion(
        n_lab=n,
        n_max=hi,
        n_min=lo,
        options={"nu_reading": nu_reading, "lattice_exact": lattice_exact},
        results=results,
        notes=notes,
    )
