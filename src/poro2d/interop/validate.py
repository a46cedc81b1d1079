"""Checks of an imported specimen, before any work: every number in a sane range, a box that
closes, disks that fit in it without sitting on one another, and gravity the check can use.

A refusal names where the value came from: the file, line and column (the readers' ``locate``),
or the command-line option that set it. The ranges (:data:`LIMITS`) are wide enough for any
granular specimen and narrow enough that nothing downstream overflows or runs for ever: densities
of real solids, stiffnesses whose time steps stay above a nanosecond, gravity pointing down the y
axis (the criterion's plate is on top; without gravity a check never comes to rest), disks
overlapping one another or a wall by at most :data:`OVERLAP_LIMIT` of a radius (a packing at rest
overlaps by far less; more is a wrong radius or unit).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from poro2d.dem.state import BOX_WALLS
from poro2d.errors import InputError
from poro2d.interop.specimen_data import SpecimenData
from poro2d.io_utils import check_input_file, text_position

#: ``locate(quantity, disk_index)``: where a value was read ("FILE line L column C (name)"),
#: or the option that gave it
Locate = Callable[..., str]


@dataclass(frozen=True)
class Limit:
    """An allowed interval with its unit; ``text`` is what a refusal prints."""

    lo: float
    hi: float
    unit: str = ""
    lo_open: bool = False
    hi_open: bool = False

    def holds(self, v: float) -> bool:
        return bool(self.holding(np.float64(v)))

    def holding(self, values) -> np.ndarray:
        """Which of ``values`` lie within the limit (NaN does not)."""
        v = np.asarray(values, dtype=float)
        above = v > self.lo if self.lo_open else v >= self.lo
        below = v < self.hi if self.hi_open else v <= self.hi
        return above & below

    @property
    def text(self) -> str:
        lo_s, hi_s = ("(" if self.lo_open else "["), (")" if self.hi_open else "]")
        return f"{lo_s}{self.lo:g}, {self.hi:g}{hi_s}" + (f" {self.unit}" if self.unit else "")


LIMITS = {
    "thickness": Limit(0.0, 1.0, "m", lo_open=True),
    "density": Limit(1.0, 1e5, "kg/m3"),
    "kn": Limit(1.0, 1e12, "N/m"),
    "ks": Limit(0.0, 1e12, "N/m"),
    "mu": Limit(0.0, 10.0),
    "radius": Limit(1e-6, 1e3, "m"),
    "coordinate": Limit(-1e3, 1e3, "m"),
    "gravity": Limit(1e-3, 1e3, "m/s2"),
    "local_damping": Limit(0.0, 1.0, hi_open=True),
    "window": Limit(0.0, 1.0, lo_open=True),
}
#: a disk may overlap another disk, or a wall, by at most this fraction of its (smaller) radius
OVERLAP_LIMIT = 0.2


def check_value(where: str, value: float, limit: Limit, what: str = "") -> float:
    """``value`` within ``limit``, or an InputError naming ``where``."""
    if not limit.holds(float(value)):
        raise InputError(where, _message_value(value), (what + " " if what else "") + limit.text)
    return float(value)


def check_imported(spec: SpecimenData, locate: Locate) -> None:
    """Refuse ``spec`` (InputError at the first bad value) unless the check can run on it."""
    with np.errstate(all="ignore"):  # the checks compare; an overflow can only mean a refusal
        _settings(spec, locate)
        _disk_values(spec, locate, ("radius", "x", "y"))
        box = _walls(spec, locate)
        _disks_in_box(spec, box, locate)
        _overlaps(spec, locate)
        _solid_area(spec, box, locate)
        _disk_values(spec, locate, ("density", "kn", "ks", "mu"))


def _message_value(v) -> float | int:
    """A value as an error message shows it: an int stays an int, a NumPy number is a float."""
    return v if isinstance(v, int) else float(v)


def _settings(spec: SpecimenData, locate: Locate) -> None:
    check_value(locate("thickness"), spec.thickness, LIMITS["thickness"])
    gx, gy = spec.gravity
    g = LIMITS["gravity"]
    down = f"downward, -{g.hi:g} to -{g.lo:g} {g.unit} (the plate is on top; zero gravity never settles)"
    if not (gy < 0 and g.holds(-gy)):
        raise InputError(locate("gravity_y"), _message_value(gy), down)
    if abs(gx) > 1e-9 * abs(gy):
        raise InputError(locate("gravity_x"), _message_value(gx), "0 (gravity along -y, the box's vertical)")
    check_value(locate("local_damping"), spec.local_damping, LIMITS["local_damping"])
    if spec.dt is not None and not spec.dt > 0.0:
        automatic = "a time step > 0 s, or 0 for the automatic step"
        raise InputError(locate("dt"), _message_value(spec.dt), automatic)
    if spec.force_fraction is not None:
        check_value(locate("window"), spec.force_fraction, LIMITS["window"], "a fraction of G in")


def _disk_values(spec: SpecimenData, locate: Locate, names: tuple[str, ...]) -> None:
    for name in names:
        values = getattr(spec, name)
        limit = LIMITS.get(name, LIMITS["coordinate"])
        bad = np.flatnonzero(~limit.holding(values))
        if bad.size:
            raise InputError(locate(name, int(bad[0])), _message_value(values[bad[0]]), limit.text)


def _walls(spec: SpecimenData, locate: Locate) -> tuple[float, float, float, float]:
    names = [w.name for w in spec.walls]
    for w in spec.walls:
        if names.count(w.name) > 1 or w.name not in BOX_WALLS:
            allowed = f"one wall each named {', '.join(BOX_WALLS)} (the criterion's box)"
            raise InputError(locate(f"wall:{w.name}:name"), w.name, allowed)
        for field in ("x0", "y0", "x1", "y1"):
            check_value(locate(f"wall:{w.name}:{field}"), getattr(w, field), LIMITS["coordinate"])
        for field in ("kn", "ks", "mu"):
            check_value(locate(f"wall:{w.name}:{field}"), getattr(w, field), LIMITS[field])
    try:
        box = spec.box()
    except InputError as exc:
        raise InputError(locate("walls"), exc.value, exc.allowed) from None
    first = spec.wall(BOX_WALLS[0])
    for w in spec.walls:
        for field in ("kn", "ks", "mu"):
            if getattr(w, field) != getattr(first, field):
                raise InputError(
                    locate(f"wall:{w.name}:{field}"), _message_value(getattr(w, field)),
                    f"{getattr(first, field)!r} as the {first.name} wall (one set of properties for the box)",
                )  # fmt: skip
    return box


def _disks_in_box(spec: SpecimenData, box, locate: Locate) -> None:
    xlo, xhi, ylo, yhi = box
    r = spec.radius
    half = 0.5 * min(xhi - xlo, yhi - ylo)
    limit = OVERLAP_LIMIT
    big = np.flatnonzero(r * (1.0 - limit) > half)
    if big.size:
        i = int(big[0])
        raise InputError(
            locate("radius", i), _message_value(r[i]),
            f"a disk that fits the box {xhi - xlo:.4g} m x {yhi - ylo:.4g} m (radius at most "
            f"{half / (1.0 - limit):.4g} m)",
        )  # fmt: skip
    for name, c, lo, hi in (("x", spec.x, xlo, xhi), ("y", spec.y, ylo, yhi)):
        lo_c, hi_c = lo + (1.0 - limit) * r, hi - (1.0 - limit) * r
        bad = np.flatnonzero(~((c >= lo_c) & (c <= hi_c)))
        if bad.size:
            i = int(bad[0])
            raise InputError(
                locate(name, i), _message_value(c[i]),
                f"[{lo_c[i]:.6g}, {hi_c[i]:.6g}] m: inside the box [{lo:.6g}, {hi:.6g}] m, overlapping a "
                f"wall by at most {limit:g} of the radius {r[i]:.4g} m",
            )  # fmt: skip


def _overlaps(spec: SpecimenData, locate: Locate) -> None:
    """No two disks overlapping by more than :data:`OVERLAP_LIMIT` of the smaller radius."""
    from scipy.spatial import cKDTree

    pos = np.column_stack([spec.x, spec.y])
    r = spec.radius
    if spec.n < 2:
        return
    pairs = cKDTree(pos).query_pairs(2.0 * float(r.max()), output_type="ndarray")
    if not len(pairs):
        return
    i, j = pairs[:, 0], pairs[:, 1]
    dist = np.hypot(*(pos[i] - pos[j]).T)
    overlap = r[i] + r[j] - dist
    too_deep = np.flatnonzero(overlap > OVERLAP_LIMIT * np.minimum(r[i], r[j]))
    if too_deep.size:
        k = too_deep[np.argmin(np.maximum(i, j)[too_deep])]  # the pair whose later disk comes first
        a, b = sorted((int(i[k]), int(j[k])))
        raise InputError(
            locate("x", b), _message_value(spec.x[b]),
            f"a centre apart from that of the disk of {locate('disk', a)}",
            f"the two overlap by {overlap[k]:.3g} m, more than {OVERLAP_LIMIT:g} of the smaller radius "
            f"{min(r[a], r[b]):.3g} m",
        )  # fmt: skip


def _solid_area(spec: SpecimenData, box, locate: Locate) -> None:
    xlo, xhi, ylo, yhi = box
    area = (xhi - xlo) * (yhi - ylo)
    solid = float(np.sum(math.pi * spec.radius**2))
    if not solid < area:
        raise InputError(
            locate("disks"), f"{spec.n} disks of {solid:.4g} m2",
            f"a solid area below the box area {area:.4g} m2 (a box porosity n' in (0, 1))",
        )  # fmt: skip


def text_of(path, what: str) -> str:
    """The text of ``path`` (UTF-8, a byte-order mark allowed), or an InputError naming the file,
    line and column of the first byte that is not text. Only a regular file of a sane size is
    read (:func:`poro2d.io_utils.check_input_file`)."""
    check_input_file(what, path)
    try:
        with open(path, "rb") as fh:
            data = fh.read()
    except OSError as exc:
        raise InputError(what, str(path), "a readable file", exc.strerror or str(exc)) from None
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        bad = exc.start + (3 if data.startswith(b"\xef\xbb\xbf") else 0)
        raise _not_text(path, data, bad, f"byte 0x{data[bad]:02x}") from None
    nul = data.find(b"\x00")
    if nul >= 0:
        raise _not_text(path, data, nul, "a NUL byte")
    return text


def _not_text(path, data: bytes, at: int, found: str) -> InputError:
    line, column = text_position(data, at)
    return InputError(f"{path} line {line} column {column}", found, "UTF-8 text (not a binary file)")
