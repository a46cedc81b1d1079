"""`poro2d import` refuses a bad specimen before any work, on one line naming the file, line
and column (or the option as typed), the value and the allowed range; and it judges a
specimen by the force window it was accepted with."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

from poro2d.cli import main
from poro2d.errors import InputError
from poro2d.interop import csv_table
from poro2d.interop import lammps as lmp
from poro2d.interop.check import read_specimen
from poro2d.interop.specimen_data import from_checkpoint
from poro2d.interop.validate import OVERLAP_LIMIT, check_imported


@pytest.fixture(scope="module")
def spec(saved):
    return from_checkpoint(saved)


def refused(argv, capsys, *words) -> str:
    """``poro2d import ...`` exits 2 with one line ``error: ...`` holding every word; no output folder."""
    out = [a for a in argv if str(a).endswith("out")]
    with pytest.raises(SystemExit) as e:
        main([str(a) for a in argv])
    err = capsys.readouterr().err.strip()
    assert e.value.code == 2, err
    lines = err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("error:"), err
    for w in words:
        assert w in lines[0], (w, lines[0])
    assert not any(Path(p).exists() for p in out)
    return lines[0]


# ------------------------------------------------------------------ CSV files
def _csv(spec, tmp_path):
    csv_table.write_specimen(spec, tmp_path)
    return tmp_path / "disks.csv", tmp_path / "walls.csv"


def _line_of(path, start: str) -> int:
    return next(k for k, ln in enumerate(path.read_text().splitlines(), 1) if ln.startswith(start))


def _set_cell(path, row_start: str, column: int, value: str) -> int:
    """Write ``value`` into a cell of the row starting with ``row_start``; returns its line."""
    lines = path.read_text().splitlines()
    k = _line_of(path, row_start)
    cells = lines[k - 1].split(",")
    cells[column - 1] = value
    lines[k - 1] = ",".join(cells)
    path.write_text("\n".join(lines) + "\n")
    return k


def _replace(path, old: str, new: str) -> int:
    text = path.read_text()
    assert old in text
    path.write_text(text.replace(old, new, 1))
    return _line_of(path, new.splitlines()[0]) if new else 0


CSV_CELLS = [
    # (disk row, column, value, words in the message)
    ("3,", 4, "-0.002", ["(radius_m)", "-0.002", "[1e-06, 1000] m"]),
    ("3,", 2, "1e308", ["(x_m)", "1e+308", "[-1000, 1000] m"]),
    ("3,", 2, "0.2", ["(x_m)", "0.2", "inside the box [0, 0.06] m"]),
    ("3,", 4, "0.5", ["(radius_m)", "0.5", "a disk that fits the box 0.06 m x 0.03 m"]),
    ("3,", 1, "2", ["(id)", "'2'", "an id of its own"]),
    ("3,", 1, "abc", ["(id)", "'abc'", "a whole number >= 1"]),
    ("3,", 2, "nan", ["'nan'", "a finite number"]),
    ("3,", 8, "1e6", ["(mu)", "[0, 10]"]),
    ("3,", 5, "inf", ["'inf'", "a finite number"]),
]


@pytest.mark.parametrize("row, column, value, words", CSV_CELLS, ids=[f"{c[1]}={c[2]}" for c in CSV_CELLS])
def test_bad_disk_cells_name_file_line_and_column(spec, tmp_path, capsys, row, column, value, words):
    disks, _ = _csv(spec, tmp_path)
    k = _set_cell(disks, row, column, value)
    line = refused(
        ["import", disks, "--out", tmp_path / "out"], capsys, f"disks.csv line {k} column {column}", *words
    )
    assert "Warning" not in line


def test_a_negative_wall_kn_names_the_walls_file(spec, tmp_path, capsys):
    _, walls = _csv(spec, tmp_path)
    k = _set_cell(walls, "bottom,", 6, "-1e7")
    refused(
        ["import", walls.parent, "--out", tmp_path / "out"],
        capsys,
        f"walls.csv line {k} column 6",
        "-10000000.0",
    )


CSV_NOTES = [
    # (note as written, as changed, column, words)
    ("# poro2d thickness 0.008", "# poro2d thickness -0.008", 4, ["(thickness)", "(0, 1] m"]),
    ("# poro2d settings 0.0 -9.81", "# poro2d settings 0.0 0.0", 5, ["(gravity_y)", "downward"]),
    ("# poro2d settings 0.0 -9.81", "# poro2d settings 0.0 9.81", 5, ["(gravity_y)", "= 9.81", "downward"]),
    ("# poro2d settings 0.0 -9.81", "# poro2d settings 2.0 -9.81", 4, ["(gravity_x)", "0 (gravity along -y"]),
    (
        "# poro2d settings 0.0 -9.81 0.7 ",
        "# poro2d settings 0.0 -9.81 0.7 -",
        7,
        ["(dt)", "a time step > 0 s"],
    ),
    ("# poro2d settings 0.0 -9.81 0.7 ", "# poro2d settings 0.0 -9.81 0.7 1", 7, ["(dt)", "critical step"]),
    ("# poro2d settings 0.0 -9.81 0.7", "# poro2d settings 0.0 -9.81 1.7", 6, ["(local_damping)", "[0, 1)"]),
]


@pytest.mark.parametrize("old, new, column, words", CSV_NOTES, ids=[c[1] for c in CSV_NOTES])
def test_bad_settings_name_their_line_and_column(spec, tmp_path, capsys, old, new, column, words):
    disks, _ = _csv(spec, tmp_path)
    k = _replace(disks, old, new)
    refused(
        ["import", disks, "--out", tmp_path / "out"], capsys, f"disks.csv line {k} column {column}", *words
    )


def test_malformed_tables(spec, tmp_path, capsys):
    disks, walls = _csv(spec, tmp_path)
    out = tmp_path / "out"
    text = disks.read_text()
    header = next(ln for ln in text.splitlines() if ln.startswith("id,"))
    cases = [
        ("", ["an empty table"]),
        (header + "\n", ["'no disks'"]),
        (text.replace(",3.0\n", ",3.0,7\n", 1), ["column 9", "an extra cell"]),
        (text.replace(",3.0\n", "\n", 1), ["column 8", "no cell"]),
        (text + "# poro2d thickness 0.009\n", ["one '# poro2d thickness' line"]),
    ]
    for body, words in cases:
        disks.write_text(body)
        refused(["import", disks, "--out", out], capsys, "disks.csv", *words)
    disks.write_bytes(b"id,x_m\n\x89PNG\r\n\x1a\n\x00\x00")
    refused(["import", disks, "--out", out], capsys, "disks.csv line 2 column 1", "byte 0x89", "UTF-8 text")
    disks.write_text(text)
    walls.write_text(walls.read_text().replace("right,", "left,"))
    refused(["import", disks, "--out", out], capsys, "walls.csv line", "(name)", "'left'", "one wall each")


def test_a_byte_order_mark_and_windows_line_ends_are_read(spec, tmp_path):
    disks, _ = _csv(spec, tmp_path)
    disks.write_bytes(b"\xef\xbb\xbf" + disks.read_text().replace("\n", "\r\n").encode())
    back = read_specimen(disks)
    assert np.array_equal(back.x, spec.x) and back.thickness == spec.thickness


def test_overlapping_disks_are_refused(spec, tmp_path, capsys):
    disks, _ = _csv(spec, tmp_path)
    j = 5  # put disk 5's centre half a radius from disk 4's
    r = spec.radius[j - 1]
    k = _set_cell(disks, f"{j},", 2, repr(float(spec.x[j - 2] + 0.5 * r)))
    _set_cell(disks, f"{j},", 3, repr(float(spec.y[j - 2])))
    refused(["import", disks, "--out", tmp_path / "out"], capsys, f"line {k} column 2", "overlap by", "0.2")


def test_more_solid_than_box_is_refused():
    """Disks overlapping each other and the walls just within the limit, but filling more than
    the box: a negative porosity is refused."""
    from poro2d.interop.lammps import box_walls
    from poro2d.interop.specimen_data import SpecimenData

    r, s = 1e-3, 1.8e-3 * (1 + 1e-9)  # neighbours overlap by 0.2 r: the limit
    xs, ys = np.meshgrid(np.arange(6) * s, np.arange(7) * s * np.sqrt(3) / 2)
    xs = xs + (np.arange(7)[:, None] % 2) * s / 2
    x, y = xs.ravel() + 0.8 * r, ys.ravel() + 0.8 * r
    width, height = float(x.max() + 0.8 * r), float(y.max() + 0.8 * r)
    n = x.size
    one = np.ones(n)
    spec = SpecimenData(x, y, r * one, 2650 * one, 4e5 * one, 4e5 * one, 0.5 * one, 0.008,
                        box_walls(0.0, width, 0.0, height, 1e7, 1e7, 0.5))  # fmt: skip
    assert np.pi * r * r * n > width * height
    with pytest.raises(InputError, match=r"below the box area"):
        check_imported(spec, lambda q, i=None: q)
    assert OVERLAP_LIMIT == 0.2


# ------------------------------------------------------------------ LAMMPS data files
def _atom_line(path, ident: int) -> int:
    lines = path.read_text().splitlines()
    start = next(k for k, ln in enumerate(lines) if ln.startswith("Atoms"))
    return next(k for k, ln in enumerate(lines[start:], start + 1) if ln.split()[:1] == [str(ident)])


def _set_word(path, line: int, column: int, value: str) -> None:
    lines = path.read_text().splitlines()
    words = lines[line - 1].split()
    words[column - 1] = value
    lines[line - 1] = " ".join(words)
    path.write_text("\n".join(lines) + "\n")


LMP_WORDS = [
    (7, "0.18", ["(z)", "one plane", "z spread here 0.18 m"]),
    (1, "2", ["(id)", "an id of its own"]),
    (1, "2.5", ["(id)", "a whole number >= 1"]),
    (1, "abc", ["'abc'", "a number"]),
    (5, "0.5", ["(x)", "inside the box"]),
    (3, "-0.004", ["(diameter)", "a diameter in [2e-06, 2000] m"]),
    # a huge or non-finite radius, refused where it is read (no overflow on the way)
    (3, "1e308", ["(diameter) = 1e+308", "a diameter in [2e-06, 2000] m"]),
    (3, "inf", ["'inf'", "a finite number"]),
    (3, "1.0", ["(radius: half the diameter) = 0.5", "a disk that fits the box"]),
    # a second atom type would be read with the first's properties
    (2, "2", ["(type) = 2", "one atom type"]),
]


@pytest.mark.parametrize("column, value, words", LMP_WORDS, ids=[f"{c[0]}={c[1]}" for c in LMP_WORDS])
def test_bad_atoms_name_file_line_and_column(spec, tmp_path, capsys, column, value, words):
    lmp.write_specimen(spec, tmp_path)
    data = tmp_path / lmp.DATA_FILE
    k = _atom_line(data, 3)
    _set_word(data, k, column, value)
    refused(
        ["import", data, "--out", tmp_path / "out"], capsys, f"specimen.data line {k} column {column}", *words
    )


def test_lammps_notes_and_sections(spec, tmp_path, capsys):
    lmp.write_specimen(spec, tmp_path)
    data = tmp_path / lmp.DATA_FILE
    text = data.read_text()
    out = tmp_path / "out"
    for old, new, words in (
        ("# poro2d settings 0.0 -9.81", "# poro2d settings 0.0 9.81", ["column 5 (gravity_y)", "downward"]),
        ("# poro2d thickness 0.008", "# poro2d thickness -0.008", ["column 4 (thickness)", "(0, 1] m"]),
        ("# poro2d wall bottom -0.06 0.0 0.12 0.0 10000000.0", "# poro2d wall bottom -0.06 0.0 0.12 0.0 -1e7",
         ["column 9 (wall bottom kn)", "[1, 1e+12] N/m"]),
        ("Atoms # sphere", "Atoms # atomic", ["'Atoms # sphere'"]),
    ):  # fmt: skip
        assert old in text, old
        data.write_text(text.replace(old, new, 1))
        k = _line_of(data, new)
        refused(["import", data, "--out", out], capsys, f"specimen.data line {k}", *words)
    cut = text[: text.index("Atoms") + 300]  # a truncated Atoms section
    data.write_text(cut)
    refused(["import", data, "--out", out], capsys, "specimen.data line", "numbers")
    data.write_text(text[: text.index("Atoms")])
    refused(["import", data, "--out", out], capsys, "Atoms section", "'0 atoms'", f"{spec.n} atoms, as line")
    data.write_bytes(bytes(range(256)))
    refused(["import", data, "--out", out], capsys, "specimen.data line", "column", "UTF-8 text")


def test_a_second_note_or_atom_type_line_is_refused_naming_both_lines(spec, tmp_path, capsys):
    """Only one of two wall lines of a name (or two thickness lines) could be read: the second is
    refused with the line of the first; so is a header of two atom types."""
    lmp.write_specimen(spec, tmp_path)
    data = tmp_path / lmp.DATA_FILE
    text = data.read_text()
    out = tmp_path / "out"
    for start in ("# poro2d wall top ", "# poro2d thickness "):
        first = _line_of(data, start)
        lines = text.splitlines()
        data.write_text("\n".join([*lines[:first], lines[first - 1], *lines[first:]]) + "\n")
        refused(["import", data, "--out", out], capsys, f"specimen.data line {first + 1} = '{start.strip()}",
                f"one such line (line {first} has it)")  # fmt: skip
    data.write_text(text.replace("\n1 atom types\n", "\n2 atom types\n"))
    k = _line_of(data, "2 atom types")
    refused(["import", data, "--out", out], capsys, f"line {k} column 1 (atom types) = '2'", "one atom type")


def test_lammps_image_flags_must_be_zero(spec, tmp_path, capsys):
    lmp.write_specimen(spec, tmp_path)
    data = tmp_path / lmp.DATA_FILE
    k = _atom_line(data, 3)
    lines = data.read_text().splitlines()
    lines[k - 1] += " 1 0 0"
    data.write_text("\n".join(lines) + "\n")
    refused(["import", data, "--out", tmp_path / "out"], capsys, f"line {k} column 8 (image flag x)", "1.0")


# ------------------------------------------------------------------ options
OPTIONS = [
    (["--friction", "-1"], ["--friction = -1.0", "[0, 10]"]),
    (["--wall-friction", "-1"], ["--wall-friction = -1.0", "[0, 10]"]),
    (["--kn", "inf"], ["--kn = inf", "[1, 1e+12] N/m"]),
    (["--ks", "nan"], ["--ks = nan", "[0, 1e+12] N/m"]),
    (["--thickness", "inf"], ["--thickness = inf", "(0, 1] m"]),
    (["--thickness", "1e300"], ["--thickness = 1e+300", "(0, 1] m"]),
    (["--density", "inf"], ["--density = inf", "[1, 100000] kg/m3"]),
    (["--window", "0"], ["--window = 0.0", "(0, 1]"]),
    (["--threads", "0"], ["--threads = 0"]),
    (["--max-steps", "99999999999"], ["--max-steps", "[1000, 100000000]"]),
]


@pytest.mark.parametrize("option, words", OPTIONS, ids=[" ".join(o[0]) for o in OPTIONS])
def test_options_are_named_as_typed_with_finite_ranges(spec, tmp_path, capsys, option, words):
    lmp.write_specimen(spec, tmp_path)
    line = refused(["import", tmp_path / lmp.DATA_FILE, "--out", tmp_path / "out", *option], capsys, *words)
    assert "inf]" not in line and "inf)" not in line


def test_a_file_of_another_origin_takes_the_given_density(spec, tmp_path):
    lmp.write_specimen(spec, tmp_path)
    data = tmp_path / lmp.DATA_FILE
    data.write_text("\n".join(ln for ln in data.read_text().splitlines() if not ln.startswith("#")) + "\n")
    assert np.allclose(read_specimen(data).density, 2650.0)  # from the file's masses
    given = read_specimen(data, {"solid_density": 3000.0, "density_given": True})
    assert np.all(given.density == 3000.0)


# ------------------------------------------------------------------ the force window
def test_export_carries_the_window_and_import_uses_it(saved, tmp_path, capsys):
    """A specimen accepted at a 5 % window (as ``paper --quick``) passes the import check at 5 %;
    at the paper's 1 % (or ``--window 0.01``) its plate, carrying about 1.3 % of G, fails."""
    folder = tmp_path / "criterion"
    folder.mkdir()
    (folder / "specimen.npz").write_bytes(saved.read_bytes())
    (folder / "result.json").write_text(json.dumps({"settings": {"force_fraction": 0.05}}))
    spec = from_checkpoint(folder)
    assert spec.force_fraction == 0.05
    main(["export", str(folder), "--to", "csv", "--out", str(tmp_path / "csv")])
    main(["export", str(folder), "--to", "lammps", "--out", str(tmp_path / "lmp")])
    assert "# poro2d window 0.05" in (tmp_path / "csv" / "disks.csv").read_text()
    assert "# poro2d window 0.05" in (tmp_path / "lmp" / lmp.DATA_FILE).read_text()
    capsys.readouterr()
    for source in (tmp_path / "csv" / "disks.csv", tmp_path / "lmp" / lmp.DATA_FILE):
        out = tmp_path / f"check-{source.suffix}"
        main(["import", str(source), "--out", str(out), "--quiet"])  # passes: exits 0
        rep = json.loads((out / "check.json").read_text())
        assert rep["passes"] and rep["criterion_settings"]["force_fraction"] == 0.05
        assert rep["window_from"] == "the file"
        assert 0.01 < rep["f_top_n_per_m"] / rep["self_weight_n_per_m"] < 0.05
        assert re.search(r"0 < F_top < 5 % of G \(the file\)", capsys.readouterr().out)
    with pytest.raises(SystemExit) as e:  # the paper's window, asked for
        main(
            [
                "import",
                str(tmp_path / "csv"),
                "--out",
                str(tmp_path / "strict"),
                "--quiet",
                "--window",
                "0.01",
            ]
        )
    assert e.value.code == 1
    assert json.loads((tmp_path / "strict" / "check.json").read_text())["window_from"] == "--window"
    # the folder of an import that failed its check is no specimen to export; one that passed is
    strict = tmp_path / "strict"
    words = str(strict / "check.json"), "says passes = False: F_top = ", "outside the window 0 < F_top < "
    refused(["export", strict, "--to", "csv", "--out", tmp_path / "again-out"], capsys, *words)
    main(["export", str(tmp_path / "check-.csv"), "--to", "csv", "--out", str(tmp_path / "passed")])
    assert (tmp_path / "passed" / "disks.csv").is_file()


def test_the_box_of_a_file_of_another_origin_is_checked_on_its_line(spec, tmp_path, capsys):
    lmp.write_specimen(spec, tmp_path)
    data = tmp_path / lmp.DATA_FILE
    text = "\n".join(ln for ln in data.read_text().splitlines() if not ln.startswith("#")) + "\n"
    xline = next(ln for ln in text.splitlines() if ln.endswith("xlo xhi"))
    lo, hi = xline.split()[:2]
    for new, words in ((f"{hi} {lo} xlo xhi", ["column 2 (xhi)", "above xlo"]),
                       ("-1e308 1e308 xlo xhi", ["column 1 (xlo)", "[-1000, 1000] m"])):  # fmt: skip
        data.write_text(text.replace(xline, new))
        k = _line_of(data, new)
        refused(["import", data, "--out", tmp_path / "out"], capsys, f"specimen.data line {k}", *words)


def test_an_option_for_what_the_file_sets_is_refused_not_ignored(spec, saved, tmp_path, capsys):
    disks, _ = _csv(spec, tmp_path / "csv")
    refused(["import", disks, "--out", tmp_path / "out", "--kn", "1e6"], capsys, "--kn = 1000000.0",
            "the file sets it", "column 6 (kn_n_per_m)")  # fmt: skip
    lmp.write_specimen(spec, tmp_path / "lmp")
    refused(["import", tmp_path / "lmp" / lmp.DATA_FILE, "--out", tmp_path / "out", "--wall-friction", "0.3"],
            capsys, "--wall-friction = 0.3", "(wall top mu)")  # fmt: skip
    refused(["import", saved, "--out", tmp_path / "out", "--thickness", "0.01"], capsys, "a checkpoint")


def test_a_refused_import_leaves_a_folder_of_other_files_as_it_was(spec, tmp_path, capsys):
    """The file is read and checked before the output folder is claimed: no kind marker is left."""
    lmp.write_specimen(spec, tmp_path)
    data = tmp_path / lmp.DATA_FILE
    data.write_text(data.read_text().replace("\n1 atom types\n", "\n2 atom types\n"))
    folder = tmp_path / "mine"
    folder.mkdir()
    (folder / "notes.txt").write_text("mine\n")
    refused(["import", data, "--out", folder], capsys, "(atom types) = '2'")
    assert sorted(p.name for p in folder.iterdir()) == ["notes.txt"]
