"""A specimen as two CSV tables: ``disks.csv`` and ``walls.csv``.

``disks.csv`` columns: ``id`` (1-based), ``x_m``, ``y_m``, ``radius_m``,
``density_kg_m3``, ``kn_n_per_m``, ``ks_n_per_m``, ``mu`` (per-body values, PFC 4.0).
``walls.csv`` columns: ``name``, ``x0_m``, ``y0_m``, ``x1_m``, ``y1_m``, ``kn_n_per_m``,
``ks_n_per_m``, ``mu``. Both start with ``#`` comment lines (units, the thickness
convention, poro2d's version); ``# poro2d thickness T`` and ``# poro2d settings GX GY
DAMPING DT`` are read back. Numbers are written with ``repr``: they read back to the
same float. ``pandas.read_csv(path, comment="#")`` reads either table.
"""

from __future__ import annotations

import csv
import math
import os
from pathlib import Path

import numpy as np

from poro2d.errors import InputError
from poro2d.interop.specimen_data import SpecimenData, WallData
from poro2d.io_utils import atomic_path, check_input_file

DISKS_FILE = "disks.csv"
WALLS_FILE = "walls.csv"
DISK_COLUMNS = ("id", "x_m", "y_m", "radius_m", "density_kg_m3", "kn_n_per_m", "ks_n_per_m", "mu")
WALL_COLUMNS = ("name", "x0_m", "y0_m", "x1_m", "y1_m", "kn_n_per_m", "ks_n_per_m", "mu")


def _notes(spec: SpecimenData) -> list[str]:
    return [
        *spec.header("#"),
        f"# poro2d thickness {spec.thickness!r}",
        f"# poro2d settings {spec.gravity[0]!r} {spec.gravity[1]!r} {spec.local_damping!r} "
        f"{spec.dt if spec.dt is not None else 0.0!r}",
    ]


def write_specimen(spec: SpecimenData, out: str | os.PathLike) -> list[Path]:
    """Write ``disks.csv`` and ``walls.csv`` into ``out`` (atomically); returns their paths."""
    out = Path(out)
    disks = (spec.x, spec.y, spec.radius, spec.density, spec.kn, spec.ks, spec.mu)
    rows = [[str(i + 1), *(repr(float(a[i])) for a in disks)] for i in range(spec.n)]
    wrows = [
        [w.name, *(repr(float(v)) for v in (w.x0, w.y0, w.x1, w.y1, w.kn, w.ks, w.mu))] for w in spec.walls
    ]
    paths = []
    for name, columns, body in ((DISKS_FILE, DISK_COLUMNS, rows), (WALLS_FILE, WALL_COLUMNS, wrows)):
        with atomic_path(out / name) as tmp, open(tmp, "w", newline="") as fh:
            fh.write("\n".join(_notes(spec)) + "\n")
            w = csv.writer(fh, lineterminator="\n")
            w.writerow(columns)
            w.writerows(body)
        paths.append(out / name)
    return paths


def read_specimen(path: str | os.PathLike, defaults: dict) -> SpecimenData:
    """The specimen of ``disks.csv`` (or a folder holding it) and the ``walls.csv`` beside it.

    A missing thickness or settings line takes ``defaults`` (thickness, gravity,
    local_damping). A bad cell is an InputError naming the file, line and column.
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
    notes.update({k: v for k, v in wnotes.items() if k not in notes})
    if not drows:
        raise InputError(str(disks_path), "no disks", "at least one disk row")
    a = np.array([[_number(disks_path, k, c, v) for c, v in enumerate(r[1:], start=2)] for k, r in drows])
    walls = []
    for k, r in wrows:
        walls.append(WallData(r[0], *(_number(walls_path, k, c, v) for c, v in enumerate(r[1:], start=2))))
    t = _setting(notes, "thickness", 1, disks_path)
    settings = _setting(notes, "settings", 4, disks_path)
    gravity = (settings[0], settings[1]) if settings else (0.0, -float(defaults["gravity"]))
    return SpecimenData(
        x=a[:, 0], y=a[:, 1], radius=a[:, 2], density=a[:, 3], kn=a[:, 4], ks=a[:, 5], mu=a[:, 6],
        thickness=t[0] if t else float(defaults["thickness"]), walls=walls, gravity=gravity,
        local_damping=settings[2] if settings else float(defaults["local_damping"]),
        dt=settings[3] if settings and settings[3] > 0 else None, source=str(disks_path),
    )  # fmt: skip


def _read_table(path: Path, columns: tuple[str, ...]) -> tuple[dict, list[tuple[int, list[str]]]]:
    """(``# poro2d`` notes, numbered rows) of a table whose header must be ``columns``."""
    notes: dict = {}
    rows: list[tuple[int, list[str]]] = []
    header_seen = False
    check_input_file("CSV specimen", path)
    try:
        lines = path.read_text().splitlines()
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError("CSV specimen", str(path), "a readable text file", str(exc)) from None
    for k, line in enumerate(lines, start=1):
        if line.startswith("#"):
            if line.startswith("# poro2d "):
                key, *vals = line[len("# poro2d ") :].split() or [""]
                notes[key] = vals
            continue
        if not line.strip():
            continue
        cells = next(csv.reader([line]))
        if not header_seen:
            if tuple(c.strip() for c in cells) != columns:
                raise InputError(f"{path} line {k}", line, "the header " + ",".join(columns))
            header_seen = True
            continue
        if len(cells) != len(columns):
            raise InputError(f"{path} line {k}", line, f"{len(columns)} comma-separated cells")
        rows.append((k, [c.strip() for c in cells]))
    if not header_seen:
        raise InputError(str(path), "no header", "the header " + ",".join(columns))
    return notes, rows


def _number(path: Path, line: int, column: int, text: str) -> float:
    try:
        v = float(text)
    except ValueError:
        raise InputError(f"{path} line {line} column {column}", text, "a number") from None
    if not math.isfinite(v):
        raise InputError(f"{path} line {line} column {column}", text, "a finite number")
    return v


def _setting(notes: dict, key: str, count: int, path: Path) -> list[float] | None:
    if key not in notes:
        return None
    vals = notes[key]
    try:
        out = [float(v) for v in vals]
    except ValueError:
        out = []
    if len(out) != count or not all(math.isfinite(v) for v in out):
        raise InputError(f"{path} '# poro2d {key}' line", " ".join(vals), f"{count} finite numbers")
    return out
