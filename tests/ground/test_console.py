"""Output written to a file or a pipe: whole tables, and progress as plain lines.

pytest captures stdout and stderr, so every command here writes to something that is
not a terminal, as in a log. Tables must come out whole (no ``…``, no row cut to 80
columns) and progress displays must write plain one-line updates instead of rich's
live display.
"""

from __future__ import annotations

import io
import re

import numpy as np
import pytest

from poro2d import progress
from poro2d.console import FILE_WIDTH, OutputConsole, Table
from poro2d.dem import Every, Particles, Simulation, Walls

ELLIPSIS = "\u2026"
LONG = 0.123456789012


@pytest.fixture(autouse=True)
def _no_terminal_hints(monkeypatch):
    # environment variables by which rich would take a log for a terminal
    for var in ("COLUMNS", "FORCE_COLOR", "TTY_COMPATIBLE", "TTY_INTERACTIVE"):
        monkeypatch.delenv(var, raising=False)


def test_console_is_wide_unless_a_terminal_or_a_width_is_given():
    assert OutputConsole(file=io.StringIO()).width == FILE_WIDTH
    assert OutputConsole(file=io.StringIO(), width=50).width == 50
    assert OutputConsole(file=io.StringIO(), force_terminal=True).width < FILE_WIDTH


def _wide_table() -> Table:
    t = Table(title="twelve numbers")
    for k in range(12):
        t.add_column(f"column {k}", justify="right")
    t.add_row(*(f"{LONG * (k + 1):.12f}" for k in range(12)))
    return t


def test_wide_table_is_written_whole_to_a_file():
    buf = io.StringIO()
    OutputConsole(file=buf).print(_wide_table())
    text = buf.getvalue()
    assert ELLIPSIS not in text
    (row,) = [line for line in text.splitlines() if "0.123456789012" in line]
    for k in range(12):
        assert f"{LONG * (k + 1):.12f}" in row  # all on one line


def test_narrow_terminal_folds_numbers_instead_of_cutting_them():
    buf = io.StringIO()
    OutputConsole(file=buf, width=60).print(_wide_table())
    text = buf.getvalue()
    assert ELLIPSIS not in text
    # every digit of every header and number is there, on as many lines as it takes
    cells = [f"column {k}" for k in range(12)] + [f"{LONG * (k + 1):.12f}" for k in range(12)]
    assert sum(ch.isdigit() for ch in text) == sum(ch.isdigit() for c in cells for ch in c)


def test_criterion_table_numbers_in_full(capsys):
    from poro2d.criterion.result import CriterionResult
    from poro2d.criterion.table import print_result
    from poro2d.store import Store

    it = {
        "trial_porosity": 0.21, "particle_count": 2591, "f_top_n_per_m": 3854.123456,
        "f_bottom_n_per_m": 3855.5, "self_weight_n_per_m": 846.4321, "plate_moved": "down",
        "plate_displacement_m": -0.001234567, "new_porosity": 0.2187654, "porosity_change": 0.0087654,
        "accepted": False,
    }  # fmt: skip
    result = CriterionResult.from_dict(
        {"n_lab": 0.3434, "iterations": [it], "message": "accepted n2D = 0.15"}
    )
    print_result(result, Store("out"))
    out = capsys.readouterr().out
    assert ELLIPSIS not in out
    row = next(line for line in out.splitlines() if "2591" in line)
    for cell in ("0.210", "3854", "3856", "846.4", "down", "-1.235", "0.2188", "0.0088", "no"):
        assert cell in row


def test_shear_and_relation_tables_in_full(capsys):
    from poro2d.cli.relation import print_relation
    from poro2d.cli.shear import print_result
    from poro2d.shear.results import ShearSeriesResult

    test = {
        "normal_stress_kpa": 100.0, "peak_shear_stress_kpa": 87.654321,
        "shear_displacement_at_peak_m": 0.00345678, "peak_stress_ratio": 0.87654321,
        "end": {"shear_stress_kpa": 71.2345, "plate_displacement_mm": 0.123456},
        "max_inertial_number": 1.23456e-4, "wall_time_s": 1234.5,
    }  # fmt: skip
    series = {"tests": [test], "friction_angle_deg": None,
              "quasi_static": {"max_inertial_number": 1.2e-4, "inertial_limit": 1e-3}}  # fmt: skip
    print_result(ShearSeriesResult.from_dict(series), "out")
    rel = {
        "points": [{"n_lab": 0.3434, "relative_density": 0.886, "n2d_dem": 0.15123, "n2d_fit": 0.14987,
                    "n2d_parabolic": 0.13541, "n2d_lim_3d": 0.14012, "n2d_lim_lab": 0.10983, "flag": None}],
        "fit": None, "fit_note": "too few points for a fit",
    }  # fmt: skip
    print_relation(rel, "out")
    out = capsys.readouterr().out
    assert ELLIPSIS not in out
    shear_row = next(line for line in out.splitlines() if "87.65" in line)
    for cell in ("100", "87.65", "3.46", "0.877", "71.23", "0.123", "1.23e-04", "1234"):
        assert cell in shear_row
    rel_row = next(line for line in out.splitlines() if "0.3434" in line)
    for cell in ("0.89", "0.1512", "0.1499", "0.1354", "0.1401", "0.1098", "ok"):
        assert cell in rel_row


def test_progress_lines_at_most_one_per_interval():
    now = [100.0]
    lines = progress.ProgressLines(interval=10.0, clock=lambda: now[0])
    written = []
    for t in (100.0, 105.0, 109.9, 110.0, 115.0, 121.0):
        now[0] = t
        written.append(lines.write("x"))
    assert written == [False, False, False, True, False, True]
    assert lines.write("end", force=True)


def _drop(n_side: int = 6) -> Simulation:
    xs = (np.arange(n_side) + 0.5) * 2.2e-3
    pos = np.array([(x, y) for y in xs for x in xs])
    p = Particles(pos, 1e-3, 2650.0, 0.01, 1e5, 1e5, 0.5)
    return Simulation(p, Walls.box(0.0, 0.0, n_side * 2.2e-3, n_side * 2.2e-3, 1e5, 1e5, 0.5))


STEP_LINE = re.compile(
    r"^drop: ([\d,]+)/3,000 steps \((\d+) %\), [\d,]+ steps/s, [\d.,]+ M p-steps/s"
    r"(, ratio (inf|\d\.\d\de[-+]\d\d))?, elapsed \d+:\d\d:\d\d$"
)


def test_run_progress_in_a_log_is_one_line_at_the_end(capsys):
    _drop().run(3000, progress="drop")
    err = capsys.readouterr().err
    assert "\x1b" not in err and ELLIPSIS not in err  # no live display, no control codes
    (line,) = err.splitlines()
    m = STEP_LINE.match(line)
    assert m and m.group(1) == "3,000" and m.group(2) == "100"


def test_run_progress_in_a_log_writes_periodic_lines(capsys, monkeypatch):
    monkeypatch.setattr(progress, "LINE_INTERVAL_S", 0.0)  # a line at every update
    quiet = lambda sim: None  # noqa: E731
    res = _drop().run(
        3000, until_ratio=1e-12, check_every=250, reporters=[Every(500, quiet)], progress="drop"
    )
    lines = capsys.readouterr().err.splitlines()
    # one per block; the last block's line is the last line (not written twice)
    done = [int(STEP_LINE.match(line).group(1).replace(",", "")) for line in lines]
    assert done == [500, 1000, 1500, 2000, 2500, 3000] and res.steps == 3000
    assert all(", ratio " in line for line in lines)  # the ratio of the last stop test


def test_shear_bars_in_a_log(capsys):
    bars = progress.JobsProgress("direct shear", ["50 kPa", "100 kPa"])
    bars.start()
    bars.update(0, "shearing", 0.42)
    bars.update(1, "consolidating")
    assert capsys.readouterr().err == ""  # less than an interval since the start
    bars.stop()
    (line,) = capsys.readouterr().err.splitlines()
    assert re.match(r"^direct shear: 50 kPa shearing 42 %, 100 kPa consolidating, elapsed [\d:]+$", line)

    bars = progress.JobsProgress("direct shear", ["50 kPa", "100 kPa"])
    bars.start()
    bars._lines.interval = 0.0  # a line at every update
    bars.done(0)
    bars.stop()  # nothing new to report: no second line
    (line,) = capsys.readouterr().err.splitlines()
    assert line.startswith("direct shear: 50 kPa done, 100 kPa waiting, elapsed ") and "\x1b" not in line


def test_count_progress_in_a_log(capsys, monkeypatch):
    monkeypatch.setattr(progress, "LINE_INTERVAL_S", 0.0)
    with progress.CountProgress("sweep", 4) as bar:
        bar.advance()
        bar.advance("1 failed")
    lines = capsys.readouterr().err.splitlines()
    assert lines[0].startswith("sweep: 1/4 cases (25 %), elapsed ") and ", eta " in lines[0]
    assert lines[-1].startswith("sweep: 2/4 cases (50 %), 1 failed, elapsed ")
    with progress.CountProgress("sweep", 4, enabled=False) as bar:
        bar.advance()
    assert capsys.readouterr().err == ""
