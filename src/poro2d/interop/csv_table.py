"""A specimen as two CSV tables: ``disks.csv`` and ``walls.csv``.

``disks.csv`` columns: ``id`` (1-based), ``x_m``, ``y_m``, ``radius_m``,
``density_kg_m3``, ``kn_n_per_m``, ``ks_n_per_m``, ``mu`` (per-body values, PFC 4.0).
``walls.csv`` columns: ``name``, ``x0_m``, ``y0_m``, ``x1_m``, ``y1_m``, ``kn_n_per_m``,
``ks_n_per_m``, ``mu``. A specimen with rolling friction has one more column in each,
``mu_r`` (per-body rolling friction), so it reads back whole. Both start with ``#``
comment lines (units, the thickness convention, poro2d's version); ``# poro2d thickness
T``, ``# poro2d settings GX GY DAMPING DT``, the criterion's ``# poro2d window F`` and, for
contacts with a normal dashpot, ``# poro2d restitution E`` are read back. Numbers are written with
``repr``: they read back to the same float. ``pandas.read_csv(path, comment="#")`` reads either table.
"""

from __future__ import annotations

import csv
import io
import math
import os
from pathlib import Path

import numpy as np

from poro2d.dem.contact_law import MAX_ROLLING_FRICTION
from poro2d.errors import InputError
from poro2d.interop.specimen_data import SpecimenData, WallData
from poro2d.interop.validate import text_of
from poro2d.io_utils import write_texts

DISKS_FILE = "disks.csv"
WALLS_FILE = "walls.csv"
DISK_COLUMNS = ("id", "x_m", "y_m", "radius_m", "density_kg_m3", "kn_n_per_m", "ks_n_per_m", "mu")
WALL_COLUMNS = ("name", "x0_m", "y0_m", "x1_m", "y1_m", "kn_n_per_m", "ks_n_per_m", "mu")
#: the column a specimen with rolling friction adds to both tables
ROLLING_COLUMN = "mu_r"


def _notes(spec: SpecimenData) -> list[str]:
    return [
        *spec.header("#"),
        f"# poro2d thickness {spec.thickness!r}",
        f"# poro2d settings {spec.gravity[0]!r} {spec.gravity[1]!r} {spec.local_damping!r} "
        f"{spec.dt if spec.dt is not None else 0.0!r}",
        *([f"# poro2d window {spec.force_fraction!r}"] if spec.force_fraction is not None else []),
        *([f"# poro2d restitution {spec.restitution!r}"] if spec.restitution is not None else []),
    ]


def export_files(spec: SpecimenData) -> list[tuple[str, str]]:
    """(name, text) of ``disks.csv`` and ``walls.csv``."""
    rolled = spec.rolled
    disks = [spec.x, spec.y, spec.radius, spec.density, spec.kn, spec.ks, spec.mu]
    if rolled:
        disks.append(spec.rolling_friction)
    rows = [[str(i + 1), *(repr(float(a[i])) for a in disks)] for i in range(spec.n)]
    wrows = [[w.name, *(repr(float(v)) for v in (*w.numbers, w.mu_r)[: 7 + rolled])] for w in spec.walls]
    extra = (ROLLING_COLUMN,) if rolled else ()
    files = []
    tables = ((DISKS_FILE, DISK_COLUMNS + extra, rows), (WALLS_FILE, WALL_COLUMNS + extra, wrows))
    for name, columns, body in tables:
        text = io.StringIO()
        text.write("\n".join(_notes(spec)) + "\n")
        w = csv.writer(text, lineterminator="\n")
        w.writerow(columns)
        w.writerows(body)
        files.append((name, text.getvalue()))
    return files


def write_specimen(spec: SpecimenData, out: str | os.PathLike) -> list[Path]:
    """Write ``disks.csv`` and ``walls.csv`` into ``out`` (atomically); returns their paths."""
    return write_texts(out, export_files(spec))


def read_specimen(path: str | os.PathLike, defaults: dict) -> SpecimenData:
    """The specimen of ``disks.csv`` (or a folder holding it) and the ``walls.csv`` beside it.

    A missing thickness or settings line takes ``defaults`` (thickness, gravity,
    local_damping). A bad cell is an InputError naming the file, line and column; the
    specimen's ``locate`` names where each value was read, for the checks that follow
    (:func:`poro2d.interop.validate.check_imported`).
    """
    p = Path(path)
    disks_path = p / DISKS_FILE if p.is_dir() else p
    walls_path = disks_path.parent / WALLS_FILE
    for f in (disks_path, walls_path):
        if not f.is_file():
            raise InputError(
                "CSV specimen", str(f), f"an existing file ({DISKS_FILE} with {WALLS_FILE} beside it)"
            )
    notes, drows = _read_table(disks_path, DISK_COLUMNS)
    wnotes, wrows = _read_table(walls_path, WALL_COLUMNS)
    rolled = len(drows[0][1]) > len(DISK_COLUMNS) if drows else False
    notes.update({k: v for k, v in wnotes.items() if k not in notes})
    if not drows:
        raise InputError(str(disks_path), "no disks", "at least one disk row below the header")
    _check_ids(disks_path, drows)
    a = np.array([[read_number(disks_path, k, c, v) for c, v in enumerate(r[1:], start=2)] for k, r in drows])
    walls = [
        WallData(r[0], *(read_number(walls_path, k, c, v) for c, v in enumerate(r[1:], start=2)))
        for k, r in wrows
    ]
    if rolled:
        _check_rolling(disks_path, drows, a[:, 7], walls_path, wrows, [w.mu_r for w in walls])
    t = _setting(notes, "thickness", 1)
    settings = _setting(notes, "settings", 4)
    window = _setting(notes, "window", 1)
    restitution = _setting(notes, "restitution", 1)
    gravity = (settings[0], settings[1]) if settings else (0.0, -float(defaults["gravity"]))
    dt = settings[3] if settings else None
    return SpecimenData(
        x=a[:, 0], y=a[:, 1], radius=a[:, 2], density=a[:, 3], kn=a[:, 4], ks=a[:, 5], mu=a[:, 6],
        thickness=t[0] if t else float(defaults["thickness"]), walls=walls, gravity=gravity,
        local_damping=settings[2] if settings else float(defaults["local_damping"]),
        dt=dt if dt != 0.0 else None,  # 0: the automatic step (written when the specimen had none)
        source=str(disks_path), force_fraction=window[0] if window else None,
        mu_r=a[:, 7].copy() if rolled else None, restitution=restitution[0] if restitution else None,
        locate=_locator(disks_path, walls_path, drows, wrows, notes),
    )  # fmt: skip


#: the column of each quantity in disks.csv and walls.csv, and in the ``# poro2d`` note lines
_DISK_COLUMN = {name: c for c, name in enumerate(("id", "x", "y", "radius", "density", "kn", "ks", "mu"), 1)}
_WALL_COLUMN = {name: c for c, name in enumerate(("name", "x0", "y0", "x1", "y1", "kn", "ks", "mu"), 1)}
_NOTE_COLUMN = {
    "thickness": ("thickness", 4), "gravity_x": ("settings", 4), "gravity_y": ("settings", 5),
    "local_damping": ("settings", 6), "dt": ("settings", 7), "window": ("window", 4),
    "restitution": ("restitution", 4),
}  # fmt: skip


def _locator(disks_path: Path, walls_path: Path, drows, wrows, notes: dict):
    """``locate(quantity, disk)``: the file, line and column a value was read from."""
    wall_line = {r[0]: k for k, r in wrows}

    def locate(quantity: str, i: int | None = None) -> str:
        if quantity == "disk":
            return f"{disks_path} line {drows[i][0]}"
        if quantity in _DISK_COLUMN:
            name = DISK_COLUMNS[_DISK_COLUMN[quantity] - 1]
            return f"{disks_path} line {drows[i][0]} column {_DISK_COLUMN[quantity]} ({name})"
        if quantity.startswith("wall:"):
            _, wall, field = quantity.split(":")
            name = WALL_COLUMNS[_WALL_COLUMN[field] - 1]
            return f"{walls_path} line {wall_line[wall]} column {_WALL_COLUMN[field]} ({name})"
        if quantity in _NOTE_COLUMN:
            key, column = _NOTE_COLUMN[quantity]
            if key in notes:
                file, line, _ = notes[key]
                return f"{file} line {line} column {column} ({quantity})"
            if quantity == "thickness":
                return "--thickness"
            return f"{quantity} (not in {disks_path.name}: Table 1)"
        if quantity == "walls":
            return str(walls_path)
        return f"{disks_path} ({quantity})"

    return locate


def _check_ids(path: Path, rows: list[tuple[int, list[str]]]) -> None:
    """Every id a whole number >= 1, none twice."""
    seen: dict[int, int] = {}
    for k, r in rows:
        try:
            ident = int(r[0])
        except ValueError:
            ident = 0
        where = f"{path} line {k} column 1 (id)"
        if ident < 1:
            raise InputError(where, r[0], "a whole number >= 1")
        if ident in seen:
            raise InputError(where, r[0], f"an id of its own (line {seen[ident]} has it)")
        seen[ident] = k


def _check_rolling(disks_path: Path, drows, disk_mu_r, walls_path: Path, wrows, wall_mu_r) -> None:
    """Rolling friction is in [0, MAX_ROLLING_FRICTION], the range every other input of it takes,
    and given in both tables or in neither."""
    if wrows and len(wrows[0][1]) != len(WALL_COLUMNS) + 1:
        raise InputError(str(walls_path), "no mu_r column", f"a mu_r column, as {disks_path.name} has")
    column = len(DISK_COLUMNS) + 1
    allowed = f"[0, {MAX_ROLLING_FRICTION:g}]"
    for path, rows, values in ((disks_path, drows, disk_mu_r), (walls_path, wrows, wall_mu_r)):
        for (k, _), v in zip(rows, values, strict=True):
            if not 0.0 <= v <= MAX_ROLLING_FRICTION:
                raise InputError(f"{path} line {k} column {column} (mu_r)", float(v), allowed)


def _read_table(path: Path, columns: tuple[str, ...]) -> tuple[dict, list[tuple[int, list[str]]]]:
    """(``# poro2d`` notes as key: (file, line, values), numbered rows) of a table whose
    header must be ``columns``, or ``columns`` and ``mu_r`` (a specimen with rolling friction)."""
    notes: dict = {}
    rows: list[tuple[int, list[str]]] = []
    header_seen = False
    lines = text_of(path, "CSV specimen").splitlines()
    for k, line in enumerate(lines, start=1):
        if line.startswith("#"):
            if line.startswith("# poro2d "):
                key, *vals = line[len("# poro2d ") :].split() or [""]
                if key in notes:
                    raise InputError(
                        f"{path} line {k}", line, f"one '# poro2d {key}' line (line {notes[key][1]} has one)"
                    )
                notes[key] = (path, k, vals)
            continue
        if not line.strip():
            continue
        cells = next(csv.reader([line]))
        if not header_seen:
            header = tuple(c.strip() for c in cells)
            if header not in (columns, columns + (ROLLING_COLUMN,)):
                raise InputError(
                    f"{path} line {k}", line, "the header " + ",".join(columns) + f" (and {ROLLING_COLUMN})"
                )
            columns, header_seen = header, True
            continue
        if len(cells) != len(columns):
            column = min(len(cells), len(columns)) + 1
            found = "an extra cell" if len(cells) > len(columns) else "no cell"
            raise InputError(
                f"{path} line {k} column {column}",
                found,
                f"{len(columns)} comma-separated cells, as the header",
            )
        rows.append((k, [c.strip() for c in cells]))
    if not header_seen:
        raise InputError(
            str(path), "an empty table" if not rows else "no header", "the header " + ",".join(columns)
        )
    return notes, rows


def read_number(path: Path | str, line: int, column: int, text: str) -> float:
    """``text`` as a finite number, or an InputError naming its file, line and column."""
    try:
        v = float(text)
    except ValueError:
        raise InputError(f"{path} line {line} column {column}", text, "a number") from None
    if not math.isfinite(v):
        raise InputError(f"{path} line {line} column {column}", text, "a finite number")
    return v


def _setting(notes: dict, key: str, count: int) -> list[float] | None:
    """The ``count`` numbers of the ``# poro2d KEY`` line, None without one."""
    if key not in notes:
        return None
    path, line, vals = notes[key]
    if len(vals) != count:
        raise InputError(f"{path} line {line}", " ".join(vals), f"{count} numbers after '# poro2d {key}'")
    return [read_number(path, line, c, v) for c, v in enumerate(vals, start=4)]
