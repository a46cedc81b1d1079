"""Do two versions of poro2d write the same files? Run the reference commands, then compare.

A restructuring of the code must leave every command's files as they were, bit for bit, apart
from what cannot repeat (wall times, process ids, folder paths, the version string). This script
runs a fixed set of small commands into a folder and compares two such folders:

    PYTHONPATH=/old/src python benchmarks/same_files.py run /tmp/before
    PYTHONPATH=/new/src python benchmarks/same_files.py run /tmp/after
    python benchmarks/same_files.py compare /tmp/before /tmp/after

The commands: ``paper --quick``, ``relation --quick``, ``biaxial --quick``, ``critical-state``
(a small cell), ``sand`` on a two-layer box, and a 9-point ``calibrate`` on the quick preset
against a synthetic laboratory made by poro2d's own direct shear (its header says so). They take
about 25 minutes on one core. ``run --only NAME`` runs one of them.

JSON files are compared value by value with the unrepeatable keys masked; every other file
byte for byte, except tables (CSV, Parquet: the unrepeatable columns left out), checkpoints
(every array; their metadata masked as JSON is) and the HTML and Markdown reports and SVG
figures, whose text is compared with times, paths and matplotlib's random ids masked.
"""

from __future__ import annotations

import argparse
import csv
import hashlib
import io
import json
import os
import re
import subprocess
import sys
from pathlib import Path

#: JSON keys whose values cannot repeat from one run to the next
UNREPEATABLE = re.compile(
    r"(wall|elapsed|seconds|_s$|time|date|created|started|finished|pid|host|path|folder_abs|"
    r"poro2d_version|version|python|numba|numpy|platform|per_s|threads|cpu|efficiency|address|"
    r"scheduler|dashboard|worker|cluster)",
    re.I,
)
#: text patterns that cannot repeat: times, dates, absolute paths, durations
TEXT_MASKS = [
    (re.compile(r"\d{4}-\d\d-\d\dT?[ \d:.+-]*"), "<date>"),
    (re.compile(r"(/[\w.+-]+){2,}"), "<path>"),
    (re.compile(r"\d+(\.\d+)?\s*(s|min|h|ms)\b"), "<dur>"),
    (re.compile(r"[\d.]+e[+-]?\d+ particle-steps"), "<rate>"),
    (re.compile(r"\b[mp][0-9a-f]{6,14}\b"), "<svg-id>"),  # matplotlib's clip-path, marker ids: random
    (re.compile(r"\bimage[0-9a-f]{6,14}\b"), "<svg-id>"),  # and its embedded images' ids
    (re.compile(r"(time[^|<]*\|\s*|<td>[^<]*_s</td><td>)[\d.e+-]+"), r"\1<t>"),  # report time rows
]

SAND_TOML = """\
seed = 0
[soil]
name = "tiny paper sand"
reference = "the paper's reconstructed grading"
[grading]
preset = "paper"
[lab]
n_max = 0.4571
n_min = 0.3253
n = 0.40
[specimen]
width = 0.05
height = 0.025
layers = 2
[criterion]
acceptance = "plate"
[sand]
seeds = 2
mu_prep = [0.0, 0.5]
calibration_disks = 10000
"""


def _poro2d(*args: str, cwd: Path) -> None:
    cmd = [sys.executable, "-m", "poro2d.cli", *args, "--quiet"]
    print("$ poro2d", " ".join(args), flush=True)
    subprocess.run(cmd, cwd=cwd, check=True)


def _synthetic_lab(root: Path) -> Path:
    """A synthetic laboratory (poro2d's own shear of the quick paper specimen at f_p 0.8, mu_r 0.15)."""
    code = (
        "import sys; from poro2d.calibration import synthetic_lab\n"
        "synthetic_lab(sys.argv[1], [50, 100], 0.8, 0.15, sys.argv[2],"
        " settings={'max_displacement': 0.002, 'peak_window': 5e-4})\n"
    )
    spec = next((root / "paper").rglob("specimen.npz"))
    lab = root / "lab" / "lab.csv"
    lab.parent.mkdir(exist_ok=True)
    subprocess.run([sys.executable, "-c", code, str(spec), str(lab)], check=True)
    return lab


def _run_calibrate(root: Path) -> None:
    lab = _synthetic_lab(root)
    _poro2d("calibrate", "--lab", str(lab), "--preset", "paper", "--quick", "--points", "9",
            "--refine", "0", "--max-displacement", "0.002", "--keep-box-dominated", "--workers", "1",
            "--out", "calibrate", cwd=root)  # fmt: skip


def _run_sand(root: Path) -> None:
    (root / "sand.toml").write_text(SAND_TOML)
    _poro2d("sand", "sand.toml", "--workers", "1", "--out", "sand", cwd=root)


RUNS = {
    "paper": lambda root: _poro2d("paper", "--quick", "--threads", "1", "--out", "paper", cwd=root),
    "relation": lambda root: _poro2d(
        "relation", "--preset", "paper", "--quick", "--workers", "1", "--out", "relation", cwd=root
    ),  # fmt: skip
    "biaxial": lambda root: _poro2d("biaxial", "--quick", "--strain", "0.02", "--out", "biaxial", cwd=root),
    "critical-state": lambda root: _poro2d(
        "critical-state",
        "--disks",
        "200",
        "--strain",
        "0.5",
        "--window-start",
        "0.25",
        "--out",
        "critical-state",
        cwd=root,
    ),  # fmt: skip
    "sand": _run_sand,
    "calibrate": _run_calibrate,  # after paper: its laboratory shears paper's specimen
}


def run(root: Path, only: list[str] | None) -> None:
    root.mkdir(parents=True, exist_ok=True)
    os.environ["PORO2D_CACHE"] = str(root / ".cache")
    for name, job in RUNS.items():
        if not only or name in only:
            job(root)


def _masked(value):
    if isinstance(value, dict):
        return {k: ("<masked>" if UNREPEATABLE.search(k) else _masked(v)) for k, v in value.items()}
    if isinstance(value, list):
        return [_masked(v) for v in value]
    if isinstance(value, str):
        return _mask_text(value)
    return value


def _mask_text(text: str) -> str:
    for pattern, repl in TEXT_MASKS:
        text = pattern.sub(repl, text)
    return text


def _digest(path: Path) -> str:
    if path.suffix == ".json":
        try:
            data = json.loads(path.read_text())
        except ValueError:
            return "unreadable JSON"
        return json.dumps(_masked(data), sort_keys=False)
    if path.suffix == ".csv":
        return _csv_digest(path)
    if path.suffix == ".npz":
        return _npz_digest(path)
    if path.suffix == ".parquet":
        import pandas as pd

        table = pd.read_parquet(path)
        return table[[c for c in table.columns if not UNREPEATABLE.search(str(c))]].to_csv()
    if path.suffix in {".html", ".md", ".svg", ".txt", ".log"}:
        return _mask_text(path.read_text(errors="replace"))
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _csv_digest(path: Path) -> str:
    """The table with its unrepeatable columns (times, workers) masked."""
    rows = list(csv.reader(io.StringIO(path.read_text())))
    data = [r for r in rows if r and not r[0].startswith("#")]
    if not data:
        return path.read_text()
    keep = [k for k, name in enumerate(data[0]) if not UNREPEATABLE.search(name)]
    return "\n".join(",".join(r[k] for k in keep if k < len(r)) for r in data)


def _npz_digest(path: Path) -> str:
    """Every array's bytes; a JSON text array (the file's metadata) masked as JSON is."""
    import numpy as np

    parts = []
    with np.load(path, allow_pickle=False) as data:
        for name in sorted(data.files):
            arr = data[name]
            text = str(arr) if arr.dtype.kind == "U" and arr.ndim == 0 else None
            if arr.dtype == np.uint8 and arr.ndim == 1:  # a JSON document stored as its bytes
                text = arr.tobytes().decode(errors="replace")
            if text is not None:
                try:
                    parts.append(name + json.dumps(_masked(json.loads(text))))
                    continue
                except ValueError:
                    pass
            parts.append(name + hashlib.sha256(arr.tobytes()).hexdigest())
    return "\n".join(parts)


def _files(root: Path) -> dict[str, Path]:
    skip = {".cache", "__pycache__", ".digests.json"}
    return {
        str(p.relative_to(root)): p
        for p in sorted(root.rglob("*"))
        if p.is_file() and not skip & {*p.relative_to(root).parts} and not p.name.endswith((".lock", ".log"))
    }


def compare(a: Path, b: Path) -> int:
    fa, fb = _files(a), _files(b)
    only_a, only_b = sorted(fa.keys() - fb.keys()), sorted(fb.keys() - fa.keys())
    differ = [k for k in sorted(fa.keys() & fb.keys()) if _digest(fa[k]) != _digest(fb[k])]
    for k in only_a:
        print(f"only in {a}: {k}")
    for k in only_b:
        print(f"only in {b}: {k}")
    for k in differ:
        print(f"differs: {k}")
    same = len(fa.keys() & fb.keys()) - len(differ)
    print(f"{same} files the same, {len(differ)} differ, {len(only_a)} + {len(only_b)} in one folder only")
    return 1 if differ or only_a or only_b else 0


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="what", required=True)
    r = sub.add_parser("run", help="run the reference commands into FOLDER")
    r.add_argument("folder", type=Path)
    r.add_argument("--only", action="append", choices=list(RUNS))
    c = sub.add_parser("compare", help="compare two folders written by 'run'")
    c.add_argument("a", type=Path)
    c.add_argument("b", type=Path)
    args = ap.parse_args()
    if args.what == "run":
        run(args.folder, args.only)
        return 0
    return compare(args.a, args.b)


if __name__ == "__main__":
    raise SystemExit(main())
