"""Grading curves (sieve data) and drawing disk radii that follow them.

Units
-----
Sieve data come in millimetres (``size_mm``), as a laboratory reports them; a
:class:`GradingCurve` stores *model* sizes in SI metres (``sizes_m``), i.e. after the
up-scaling factor and the optional cut-offs. The cut-offs ``d_min_mm``/``d_max_mm`` are
also in millimetres and act on the up-scaled (model) sizes.

Mass and area
-------------
Percent passing is by mass. Disks of one density and one thickness have mass proportional
to area, so a class's mass fraction is its share of the total disk area.

Between two sieves, percent passing is interpolated linearly in ``log d`` (the way a grading
curve is drawn on its semi-log chart); this is used only for the cut-offs. Within a sieve
class, diameters are drawn uniformly in ``d`` (default) or uniformly in ``log d``.
"""

from __future__ import annotations

import csv
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from poro2d.errors import InputError, as_float_array, check_int, check_range, is_number
from poro2d.io_utils import check_input_file, read_utf8
from poro2d.lab_table import parse_number

__all__ = [
    "MAX_DRAW",
    "PAPER_UPSCALE",
    "GradingCurve",
    "check_upscale",
    "draw_disks",
    "max_deviation",
    "paper_grading",
    "realised_curve",
]

#: Up-scaling factor of the paper (section 3: laboratory sizes times 10).
PAPER_UPSCALE = 10.0

_WITHIN_CLASS = ("uniform", "loguniform")
_CONFIG_KEYS = ("preset", "csv", "sizes_mm", "percent_passing", "upscale", "d_min_mm", "d_max_mm")
_TOP_TOL = 1e-6  # percent passing at the largest size must be 100 within this
#: The most disks :func:`draw_disks` will draw (a hard ceiling against exhausting the memory;
#: specimens have their own, lower limit: ``SpecimenSpec.max_disks``).
MAX_DRAW = 50_000_000
#: grain sizes (mm) a grading may hold, in the laboratory and in the model: from a clay's 0.1
#: micrometre to a 10 m boulder. Beyond them a size is a typo or a unit slip, and its disk
#: areas overflow or vanish in float arithmetic.
GRAIN_RANGE_MM = (1e-4, 1e4)


def _as_float_array(name: str, values: Any) -> np.ndarray:
    arr = as_float_array(name, values)  # numbers only: ["0.2", "0.5"] is refused, not parsed
    if arr.ndim != 1:
        raise InputError(name, values, "a flat list of numbers")
    if not np.all(np.isfinite(arr)):
        raise InputError(name, values, "finite numbers")
    return arr


def _check_curve(
    sizes: np.ndarray,
    percent: np.ndarray,
    size_name: str,
    percent_name: str,
    *,
    need_zero_start: bool,
) -> None:
    """Raise InputError unless (sizes, percent) is a valid ascending grading curve."""
    if sizes.size != percent.size:
        raise InputError(percent_name, percent.tolist(), f"one value per size ({sizes.size} sizes given)")
    if sizes.size < 2:
        raise InputError(size_name, sizes.tolist(), "at least 2 sieve sizes")
    if np.any(sizes <= 0.0):
        raise InputError(size_name, sizes.tolist(), "sizes > 0")
    if np.any(np.diff(sizes) <= 0.0):
        raise InputError(
            size_name,
            sizes.tolist(),
            "strictly increasing sizes (a table listed from the coarsest sieve is also accepted)",
        )
    if np.any(percent < 0.0) or np.any(percent > 100.0):
        raise InputError(percent_name, percent.tolist(), "percentages in [0, 100]")
    if np.any(np.diff(percent) < 0.0):
        raise InputError(percent_name, percent.tolist(), "percent passing non-decreasing with size")
    if abs(percent[-1] - 100.0) > _TOP_TOL:
        raise InputError(
            percent_name,
            percent.tolist(),
            "100 % passing at the largest size",
            hint="add the sieve that everything passes",
        )
    if need_zero_start and percent[0] != 0.0:
        raise InputError(
            percent_name,
            percent.tolist(),
            "0 % passing at the smallest size",
            hint="the smallest size bounds the finest class: add the size of the finest "
            "particles with 0 %, or set d_min_mm above the smallest size to cut the fines",
        )


def _check_grain_range(name: str, sizes_mm: np.ndarray, value: Any = None) -> None:
    """Refuse sizes (mm) outside ``GRAIN_RANGE_MM``, naming ``name`` (its ``value``, or the sizes)."""
    lo, hi = GRAIN_RANGE_MM
    if sizes_mm[0] < lo or sizes_mm[-1] > hi:
        which = "sizes" if value is None else "up-scaled sizes"
        raise InputError(
            name, sizes_mm.tolist() if value is None else value,
            f"grain sizes in [{lo:g}, {hi:g}] mm (clay to boulders)",
            f"the {which} run {sizes_mm[0]:.3g}-{sizes_mm[-1]:.3g} mm",
        )  # fmt: skip


def _interp_log(x: float, sizes: np.ndarray, percent: np.ndarray) -> float:
    return float(np.interp(math.log(x), np.log(sizes), percent))


def check_upscale(value) -> float:
    """The factor every grain size is multiplied by: a finite number > 0 (NaN and inf alike named
    as not finite: the range (0, inf] would read as if inf were allowed)."""
    if is_number(value) and not math.isfinite(float(value)):
        raise InputError("upscale", value, "a finite number > 0")
    return check_range("upscale", value, 0.0, None, lo_open=True)


@dataclass(frozen=True)
class GradingCurve:
    """A grading curve of model sizes (metres) and percent passing by mass.

    Invariants (checked on construction): at least two points, sizes strictly increasing
    and > 0, percent passing non-decreasing, 0 at the smallest size and 100 at the largest.
    Build one from laboratory data with :meth:`from_lists`, :meth:`from_csv` or
    :meth:`from_config`; the plain constructor takes model sizes in metres.
    """

    sizes_m: tuple[float, ...]
    percent_passing: tuple[float, ...]
    upscale: float = 1.0
    source: str = ""

    def __post_init__(self) -> None:
        sizes = _as_float_array("sizes_m", self.sizes_m)
        percent = _as_float_array("percent_passing", self.percent_passing)
        _check_curve(sizes, percent, "sizes_m", "percent_passing", need_zero_start=True)
        percent[-1] = 100.0
        check_upscale(self.upscale)
        object.__setattr__(self, "sizes_m", tuple(float(v) for v in sizes))
        object.__setattr__(self, "percent_passing", tuple(float(v) for v in percent))
        object.__setattr__(self, "upscale", float(self.upscale))

    # ------------------------------------------------------------------ constructors
    @classmethod
    def from_lists(
        cls,
        sizes_mm: Sequence[float],
        percent_passing: Sequence[float],
        *,
        upscale: float = 1.0,
        d_min_mm: float | None = None,
        d_max_mm: float | None = None,
        source: str = "inline",
    ) -> GradingCurve:
        """Build a curve from laboratory sieve sizes (mm) and percent passing by mass.

        ``upscale`` multiplies every size. ``d_min_mm``/``d_max_mm`` cut the *up-scaled*
        curve: mass finer than ``d_min_mm`` or coarser than ``d_max_mm`` is removed and the
        rest renormalised to 0-100 %. A table listed from the coarsest sieve down is
        accepted and reversed.
        """
        sizes = _as_float_array("sizes_mm", sizes_mm)
        percent = _as_float_array("percent_passing", percent_passing)
        if sizes.size >= 2 and np.all(np.diff(sizes) < 0.0) and percent.size == sizes.size:
            sizes, percent = sizes[::-1].copy(), percent[::-1].copy()
        _check_curve(sizes, percent, "sizes_mm", "percent_passing", need_zero_start=False)
        _check_grain_range("sizes_mm", sizes)
        percent[-1] = 100.0
        up = check_upscale(upscale)
        _check_grain_range("upscale", sizes * up, upscale)
        d = sizes * up / 1000.0
        lo = _cutoff("d_min_mm", d_min_mm)
        hi = _cutoff("d_max_mm", d_max_mm)
        if lo is not None and hi is not None and lo >= hi:
            raise InputError("d_min_mm", d_min_mm, f"< d_max_mm = {d_max_mm}")
        if percent[0] > 0.0 and (lo is None or lo <= d[0]):
            _check_curve(sizes, percent, "sizes_mm", "percent_passing", need_zero_start=True)
        d, percent = _apply_cutoffs(d, percent, lo, hi, d_min_mm, d_max_mm)
        return cls(tuple(d), tuple(percent), upscale=up, source=source)

    @classmethod
    def from_csv(
        cls,
        path: str | Path,
        *,
        upscale: float = 1.0,
        d_min_mm: float | None = None,
        d_max_mm: float | None = None,
    ) -> GradingCurve:
        """Read a CSV with columns ``size_mm,percent_passing`` (lines starting ``#`` skipped)."""
        p = check_input_file("csv", path)
        # read as every laboratory file is: a byte order mark dropped, other bytes than UTF-8
        # refused naming their line and column
        text = read_utf8("csv", p, "a text (UTF-8) CSV file with columns size_mm,percent_passing")
        sizes, percent = _parse_csv(text, str(p))
        return cls.from_lists(
            sizes,
            percent,
            upscale=upscale,
            d_min_mm=d_min_mm,
            d_max_mm=d_max_mm,
            source=str(p),
        )

    @classmethod
    def from_config(cls, table: Mapping[str, Any], *, base_dir: str | Path | None = None) -> GradingCurve:
        """Build a curve from a config table (e.g. ``[grading]`` of a TOML file).

        Keys: exactly one of ``preset = "paper"``, ``csv = "path.csv"`` (relative to
        ``base_dir``) or ``sizes_mm = [...]`` with ``percent_passing = [...]``; optional
        ``upscale`` (default 1, or 10 for the paper preset), ``d_min_mm``, ``d_max_mm``. A refusal
        names the table's key as typed (``grading.upscale``).
        """
        try:
            return cls._from_table(table, base_dir)
        except InputError as exc:
            if exc.parameter not in table:
                raise
            raise InputError(f"grading.{exc.parameter}", exc.value, exc.allowed, exc.hint) from None

    @classmethod
    def _from_table(cls, table: Mapping[str, Any], base_dir: str | Path | None) -> GradingCurve:
        unknown = sorted(set(table) - set(_CONFIG_KEYS))
        if unknown:
            raise InputError(f"grading.{unknown[0]}", table[unknown[0]], ", ".join(_CONFIG_KEYS))
        sources = [k for k in ("preset", "csv", "sizes_mm") if k in table]
        if len(sources) != 1:
            raise InputError(
                "grading", sorted(table), "exactly one of preset, csv or sizes_mm/percent_passing"
            )
        _check_config_types(table)
        cuts = {"d_min_mm": table.get("d_min_mm"), "d_max_mm": table.get("d_max_mm")}
        if "preset" in table:
            if table["preset"] not in GRADING_PRESETS:
                allowed = " or ".join(f'"{k}"' for k in GRADING_PRESETS)
                raise InputError("grading.preset", table["preset"], allowed)
            if "percent_passing" in table:
                raise InputError("grading.percent_passing", table["percent_passing"], "unset")
            return preset_grading(table["preset"], upscale=table.get("upscale", PAPER_UPSCALE), **cuts)
        upscale = table.get("upscale", 1.0)
        if "csv" in table:
            if "percent_passing" in table:
                raise InputError(
                    "grading.percent_passing", table["percent_passing"], "unset when csv is given"
                )
            path = Path(table["csv"])
            if base_dir is not None and not path.is_absolute():
                path = Path(base_dir) / path
            return cls.from_csv(path, upscale=upscale, **cuts)
        if "percent_passing" not in table:
            raise InputError("grading.percent_passing", None, "a list, one value per size")
        return cls.from_lists(
            table["sizes_mm"], table["percent_passing"], upscale=upscale, source="config", **cuts
        )

    # ------------------------------------------------------------------ derived data
    @property
    def sizes(self) -> np.ndarray:
        """Model sieve sizes in metres (a new array)."""
        return np.array(self.sizes_m)

    @property
    def percent(self) -> np.ndarray:
        """Percent passing by mass (a new array)."""
        return np.array(self.percent_passing)

    @property
    def d_min_m(self) -> float:
        return self.sizes_m[0]

    @property
    def d_max_m(self) -> float:
        return self.sizes_m[-1]

    @property
    def class_fractions(self) -> np.ndarray:
        """Mass (= area) fraction of each class between consecutive sizes; sums to 1."""
        return np.diff(self.percent) / 100.0

    def mean_disk_area(self, within_class: str = "uniform") -> float:
        """Expected disk area [m^2] of a drawn set: total area / expected number of disks."""
        _check_within(within_class)
        a, b = self.sizes[:-1], self.sizes[1:]
        f = self.class_fractions
        keep = f > 0.0
        return float(1.0 / np.sum(f[keep] / _class_mean_area(a[keep], b[keep], within_class)))

    def expected_count(self, solid_area: float, within_class: str = "uniform") -> float:
        """Expected number of disks that :func:`draw_disks` returns for ``solid_area``."""
        return float(solid_area) / self.mean_disk_area(within_class)

    def size_at(self, percent: float) -> float:
        """The size [m] that ``percent`` of the mass passes (log-linear between sieves)."""
        p = check_range("percent", percent, 0.0, 100.0)
        logd = np.interp(p, self.percent, np.log(self.sizes))
        return float(np.exp(logd))

    @property
    def uniformity(self) -> float:
        """Coefficient of uniformity Cu = d60 / d10."""
        return self.size_at(60.0) / self.size_at(10.0)


def log_linear_grading(cu: float, mean_disk_area: float, sieves: int = 9) -> GradingCurve:
    """A grading of uniformity ``cu`` whose drawn disks have mean area ``mean_disk_area``.

    Percent passing grows linearly with log d from 0 at d_min to 100 at d_max, so
    Cu = d60 / d10 = (d_max / d_min)^0.5; the sizes are then scaled so that disks drawn
    from it (uniform diameter within each class) have the given mean area. A family of
    such curves varies the width of a grading at a fixed number of disks in the box.
    """
    cu = check_range("cu", cu, 1.0, 20.0, lo_open=True)
    area = check_range("mean_disk_area", mean_disk_area, 0.0, None, lo_open=True)
    sieves = check_int("sieves", sieves, 2, 50)
    unit = np.geomspace(1.0, cu**2, sieves)
    percent = np.linspace(0.0, 100.0, sieves)
    scale = math.sqrt(area / GradingCurve(tuple(unit), tuple(percent)).mean_disk_area())
    return GradingCurve(tuple(unit * scale), tuple(percent), source=f"log-linear, Cu = {cu:g}")


def _check_config_types(table: Mapping[str, Any]) -> None:
    """Refuse config values of the wrong type, e.g. ``upscale = "10"`` or ``csv = 5``."""
    for key in ("preset", "csv"):
        if key in table and not isinstance(table[key], str):
            raise InputError(f"grading.{key}", table[key], "a string")
    for key in ("upscale", "d_min_mm", "d_max_mm"):
        if key in table and not is_number(table[key]):
            raise InputError(f"grading.{key}", table[key], "a number")
    for key in ("sizes_mm", "percent_passing"):
        if key in table and not isinstance(table[key], list):
            raise InputError(f"grading.{key}", table[key], "a list of numbers")


def _cutoff(name: str, value: float | None) -> float | None:
    if value is None:
        return None
    lo, hi = GRAIN_RANGE_MM
    v = check_range(name, value, 0.0, None, lo_open=True)
    if not lo <= v <= hi:  # an infinity too
        raise InputError(name, value, f"a grain size in [{lo:g}, {hi:g}] mm")
    return v / 1000.0


def _apply_cutoffs(
    d: np.ndarray,
    percent: np.ndarray,
    lo: float | None,
    hi: float | None,
    lo_raw: Any,
    hi_raw: Any,
) -> tuple[np.ndarray, np.ndarray]:
    """Cut an up-scaled curve at lo/hi (metres), renormalise, trim empty end classes."""
    if lo is not None and lo >= d[-1]:
        raise InputError(
            "d_min_mm",
            lo_raw,
            f"< the largest up-scaled size {d[-1] * 1e3:g} mm",
            hint="the cut-offs leave no particles",
        )
    if hi is not None and hi <= d[0]:
        raise InputError(
            "d_max_mm",
            hi_raw,
            f"> the smallest up-scaled size {d[0] * 1e3:g} mm",
            hint="the cut-offs leave no particles",
        )
    lo_eff = d[0] if lo is None else max(lo, d[0])
    hi_eff = d[-1] if hi is None else min(hi, d[-1])
    p_lo = _interp_log(lo_eff, d, percent)
    p_hi = _interp_log(hi_eff, d, percent)
    if p_hi - p_lo <= 0.0:
        raise InputError(
            "d_min_mm" if lo is not None else "d_max_mm",
            lo_raw if lo is not None else hi_raw,
            "cut-offs that keep some mass of the curve",
            hint=f"no mass between {lo_eff * 1e3:g} and {hi_eff * 1e3:g} mm",
        )
    inner = (d > lo_eff) & (d < hi_eff)
    d_new = np.concatenate(([lo_eff], d[inner], [hi_eff]))
    p_new = np.concatenate(([p_lo], percent[inner], [p_hi]))
    p_new = np.clip((p_new - p_lo) / (p_hi - p_lo) * 100.0, 0.0, 100.0)
    p_new[0], p_new[-1] = 0.0, 100.0
    # trim classes of zero mass at both ends so d_min_m/d_max_m are the real bounds
    first = int(np.nonzero(p_new == 0.0)[0][-1])
    last = int(np.nonzero(p_new == 100.0)[0][0])
    return d_new[first : last + 1], p_new[first : last + 1]


def _parse_csv(text: str, origin: str) -> tuple[list[float], list[float]]:
    """The sieve curve's columns; each number is read as every laboratory file's are
    (:func:`poro2d.lab_table.parse_number`), a refusal naming its line and column."""
    if "\x00" in text:  # valid UTF-8 but binary (the csv module would stop on it with its own error)
        raise InputError("csv", origin, "a text CSV file with columns size_mm,percent_passing",
                         "it contains NUL bytes")  # fmt: skip
    numbered = [
        (k + 1, ln)
        for k, ln in enumerate(text.splitlines())
        if ln.strip() and not ln.lstrip().startswith("#")
    ]
    # each line on its own: a stray quote must not join the lines after it into one row
    rows = [next(csv.reader([ln])) for _, ln in numbered]
    fields = [f.strip() for f in rows[0]] if rows else []
    if "size_mm" not in fields or "percent_passing" not in fields:
        raise InputError("csv", origin, "a header with columns size_mm,percent_passing")
    columns = {name: fields.index(name) for name in ("size_mm", "percent_passing")}
    values: dict[str, list[float]] = {"size_mm": [], "percent_passing": []}
    for (line, _), row in zip(numbered[1:], rows[1:], strict=True):
        for name, k in columns.items():
            where = f"csv {name} (line {line}, column {k + 1} of {origin})"
            if k >= len(row):
                raise InputError(where, ",".join(row), "numbers in size_mm and percent_passing")
            values[name].append(parse_number(row[k], where))
    return values["size_mm"], values["percent_passing"]


def paper_grading(
    *,
    upscale: float = PAPER_UPSCALE,
    d_min_mm: float | None = None,
    d_max_mm: float | None = None,
) -> GradingCurve:
    """The built-in grading of the paper preset, up-scaled by 10.

    A documented *reconstruction* of a medium sand (lab d 0.2-0.71 mm), not the measured
    curve of the paper's Fig. 4; see ``docs/grading.md``. With diameters uniform within each
    class its mean disk area is 1.256e-5 m^2, which gives about 2589 disks at n2D = 0.14 and
    2559 at 0.15 in the 0.305 m x 0.124 m box (paper: 2591 and 2552).
    """
    text = resources.files("poro2d").joinpath("data/paper_grading.csv").read_text("utf-8")
    sizes, percent = _parse_csv(text, "poro2d/data/paper_grading.csv")
    return GradingCurve.from_lists(
        sizes,
        percent,
        upscale=upscale,
        d_min_mm=d_min_mm,
        d_max_mm=d_max_mm,
        source="poro2d/data/paper_grading.csv (reconstruction of the paper's Fig. 4)",
    )


#: built-in gradings: the paper's reconstruction and two wide illustrative curves with fines
#: (``data/*.csv``; none of them is a measured sand, see docs/grading.md)
GRADING_PRESETS = {
    "paper": ("paper_grading.csv", "reconstruction of the paper's Fig. 4"),
    "wide_cu4": ("wide_cu4_grading.csv", "illustrative wide grading with fines, Cu 4.3"),
    "wide_cu6": ("wide_cu6_grading.csv", "illustrative very wide grading, Cu 6.3"),
}


def preset_grading(
    name: str,
    *,
    upscale: float = PAPER_UPSCALE,
    d_min_mm: float | None = None,
    d_max_mm: float | None = None,
) -> GradingCurve:
    """A built-in grading by name (``GRADING_PRESETS``), up-scaled by 10 unless told otherwise."""
    if name == "paper":
        return paper_grading(upscale=upscale, d_min_mm=d_min_mm, d_max_mm=d_max_mm)
    if name not in GRADING_PRESETS:
        raise InputError("grading preset", name, " or ".join(f'"{k}"' for k in GRADING_PRESETS))
    file, what = GRADING_PRESETS[name]
    text = resources.files("poro2d").joinpath(f"data/{file}").read_text("utf-8")
    sizes, percent = _parse_csv(text, f"poro2d/data/{file}")
    return GradingCurve.from_lists(
        sizes, percent, upscale=upscale, d_min_mm=d_min_mm, d_max_mm=d_max_mm,
        source=f"poro2d/data/{file} ({what})",
    )  # fmt: skip


# ---------------------------------------------------------------------- drawing disks
def _check_within(within_class: str) -> None:
    if within_class not in _WITHIN_CLASS:
        raise InputError("within_class", within_class, " or ".join(_WITHIN_CLASS))


def _class_mean_area(a: np.ndarray, b: np.ndarray, within_class: str) -> np.ndarray:
    """Mean disk area in classes [a, b] of diameter for the within-class distribution."""
    if within_class == "uniform":
        mean_d2 = (a * a + a * b + b * b) / 3.0
    else:  # log-uniform: E[d^2] = (b^2 - a^2) / (2 ln(b/a))
        mean_d2 = (b * b - a * a) / (2.0 * np.log(b / a))
    return 0.25 * np.pi * mean_d2


def _sample_d(rng: np.random.Generator, a: float, b: float, n: int, within: str) -> np.ndarray:
    u = rng.random(n)
    if within == "uniform":
        return a + (b - a) * u
    return a * (b / a) ** u


def _make_rng(seed: int | np.random.Generator) -> np.random.Generator:
    if isinstance(seed, np.random.Generator):
        return seed
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or seed < 0:
        raise InputError("seed", seed, "an integer >= 0 or a numpy Generator")
    return np.random.default_rng(int(seed))


def _fill_class(
    rng: np.random.Generator,
    a: float,
    b: float,
    mean_area: float,
    target_cum: float,
    area_cum: float,
    within_class: str,
) -> tuple[list[np.ndarray], float]:
    """Diameters of one class [a, b] until the running area passes ``target_cum``.

    Drawn in batches 10 % above the expected need (plus 8 disks), so one batch nearly always
    does instead of a draw per disk; the batch sizes decide which random numbers each disk
    gets, so changing them changes the radii of a seed. The last disk is kept only if it
    brings the running area closer to the target (the cumulative curve is then tracked to
    half a disk). Returns the batches and the new running area.
    """
    chunks: list[np.ndarray] = []
    while True:
        need = target_cum - area_cum
        n = max(8, int(1.1 * max(need, 0.0) / mean_area) + 8)
        dd = _sample_d(rng, a, b, n, within_class)
        cum = area_cum + np.cumsum(0.25 * np.pi * dd * dd)
        over = np.nonzero(cum > target_cum)[0]
        if over.size == 0:
            chunks.append(dd)
            area_cum = float(cum[-1])
            continue
        k = int(over[0])
        before = area_cum if k == 0 else float(cum[k - 1])
        keep = k + 1 if cum[k] - target_cum < target_cum - before else k
        chunks.append(dd[:keep])
        area_cum = float(cum[keep - 1]) if keep > 0 else area_cum
        return chunks, area_cum


def _to_exact_area(radii: np.ndarray, area: float) -> np.ndarray:
    """One common factor on all radii, so the total area and with it the porosity are exact to rounding."""
    for _ in range(3):  # one pass is normally enough; repeat to be safe against rounding
        total = float(np.sum(np.pi * radii * radii))
        if abs(total - area) <= 1e-14 * area:
            break
        radii = radii * math.sqrt(area / total)
    return radii


def draw_disks(
    curve: GradingCurve,
    solid_area: float,
    seed: int | np.random.Generator,
    *,
    within_class: str = "uniform",
) -> np.ndarray:
    """Draw disk radii [m] whose total area is ``solid_area`` and whose area follows ``curve``.

    Classes are filled one after the other from the coarsest: each gets the target area
    ``fraction * solid_area`` plus what the previous classes missed or overshot, and its last
    disk is kept only if that brings the running total closer to the running target. So the
    cumulative area tracks the curve to within half a disk of the class being filled, and the
    total ends within half of one of the finest disks of ``solid_area``. Finally all radii are
    multiplied by one common factor ``sqrt(solid_area / total)``, within about
    ``a_fine / (4 solid_area)`` of 1 (a_fine: area of one of the finest disks; ~3e-5 for the
    paper specimen). That makes the total area exact to rounding (relative error ~1e-15), so
    the specimen porosity is exactly the trial porosity; a disk drawn at a class bound may be
    moved across it by that tiny factor.

    Within a class, diameters are uniform in ``d`` (``within_class="uniform"``) or in
    ``log d`` (``"loguniform"``). Radii are returned in drawing order (coarsest class first).
    The same seed gives the same radii.
    """
    if not isinstance(curve, GradingCurve):
        raise InputError("curve", type(curve).__name__, "a GradingCurve")
    area = check_range("solid_area", solid_area, 0.0, None, lo_open=True)
    if not math.isfinite(area):
        raise InputError("solid_area", solid_area, "a finite area in m^2 > 0")
    _check_within(within_class)
    rng = _make_rng(seed)

    d = curve.sizes
    fractions = curve.class_fractions
    lo_all, hi_all = d[:-1], d[1:]
    mean_areas = _class_mean_area(lo_all, hi_all, within_class)
    expected = curve.expected_count(area, within_class)
    if expected > MAX_DRAW:
        raise InputError(
            "solid_area", solid_area, f"at most about {MAX_DRAW:.0e} disks of this grading",
            f"it would take about {expected:.3g} disks",
        )  # fmt: skip

    chunks: list[np.ndarray] = []
    target_cum = 0.0
    area_cum = 0.0
    for i in range(fractions.size - 1, -1, -1):
        if fractions[i] <= 0.0:
            continue
        target_cum += fractions[i] * area
        a, b = float(lo_all[i]), float(hi_all[i])
        drawn, area_cum = _fill_class(rng, a, b, mean_areas[i], target_cum, area_cum, within_class)
        chunks.extend(drawn)

    diam = np.concatenate(chunks) if chunks else np.empty(0)
    if diam.size == 0:
        raise InputError(
            "solid_area",
            solid_area,
            f"at least about one disk area of the finest class ({mean_areas[0]:.3g} m^2)",
        )
    return _to_exact_area(0.5 * diam, area)


# ---------------------------------------------------------------------- checking a draw
def _radii_array(radii: Any) -> np.ndarray:
    r = _as_float_array("radii", radii)
    if r.size == 0 or np.any(r <= 0.0):
        raise InputError("radii", r.size, "a non-empty list of radii > 0")
    return r


def realised_curve(curve: GradingCurve, radii: Any) -> np.ndarray:
    """Percent passing by area of ``radii`` at the curve's sizes (a disk passes if d <= size)."""
    r = _radii_array(radii)
    order = np.argsort(r)
    d_sorted = 2.0 * r[order]
    cum = np.concatenate(([0.0], np.cumsum(r[order] ** 2)))
    idx = np.searchsorted(d_sorted, curve.sizes, side="right")
    return 100.0 * cum[idx] / cum[-1]


def max_deviation(curve: GradingCurve, radii: Any) -> float:
    """Largest |realised - requested| percent passing over the sieve sizes [percentage points]."""
    return float(np.max(np.abs(realised_curve(curve, radii) - curve.percent)))
